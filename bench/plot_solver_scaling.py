#!/usr/bin/python3
"""Time per step of the contact solvers against the number of grains (the width series of
bench/solver_scaling.sh), log-log, with the line c N log N through each method's smallest
sample: the issue's bound on the growth. Reads a CSV with the columns grains, method,
ms_per_step, iterations (one row per sample and method, as tabled in docs/performance.md)
and writes a PNG.

    /usr/bin/python3 bench/plot_solver_scaling.py docs/figures/solver_scaling.csv \
        docs/figures/solver_scaling.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(source, target):
    with open(source) as f:
        rows = list(csv.DictReader(f))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    fig, (time_ax, iter_ax) = plt.subplots(1, 2, figsize=(11, 4.5))
    for k, method in enumerate(methods):
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: float(r["grains"]))
        n = np.array([float(r["grains"]) for r in mine])
        ms = np.array([float(r["ms_per_step"]) for r in mine])
        it = np.array([float(r["iterations"]) for r in mine])
        colour = "C%d" % k
        time_ax.loglog(n, ms, "o-", color=colour, label=method)
        bound = ms[0] * n * np.log(n) / (n[0] * np.log(n[0]))
        time_ax.loglog(n, bound, ":", color=colour, lw=1)
        iter_ax.semilogx(n, it, "o-", color=colour, label=method)
    time_ax.set_xlabel("grains N")
    time_ax.set_ylabel("ms per step (one core unless the label says two threads)")
    time_ax.set_title("time per step; dotted: c N log N from the smallest sample")
    time_ax.legend(fontsize=8)
    iter_ax.set_xlabel("grains N")
    iter_ax.set_ylabel("sweeps or products per step")
    iter_ax.set_title("iterations per step")
    iter_ax.set_ylim(bottom=0)
    fig.tight_layout()
    fig.savefig(target, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_solver_scaling.py SCALING.csv OUT.png")
    main(sys.argv[1], sys.argv[2])
