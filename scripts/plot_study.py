#!/usr/bin/python3
"""Overlay plots of a study (Debian's numpy and matplotlib).

    /usr/bin/python3 scripts/plot_study.py STUDY_OUTPUT_DIR

Reads study_summary.csv and each complete case's profiles.csv; writes
profiles_overlay.png (vx, sigma_yy, sigma_xy across the gap, one curve per case, with
error bars of the batch-means standard error where profiles.csv has `*_stderr`)
and, when mu_mean is known, mu_by_case.png (mean friction with its standard
deviation against the first varied parameter, one curve per value of the second).
"""
import csv
import os
import sys

from plotting import plt, save  # noqa: E402  (scripts/plotting.py)
import numpy as np  # noqa: E402


def main(directory):
    with open(os.path.join(directory, "study_summary.csv")) as f:
        rows = list(csv.DictReader(f))
    # The varied entries: the columns between "case" and "status".
    names = list(rows[0].keys()) if rows else []
    varied = names[1:names.index("status")] if "status" in names else []
    label = lambda r: ", ".join(f"{k.split('/')[-1]}={r[k]}" for k in varied) or r["case"]

    fig, axes = plt.subplots(1, 3, figsize=(11, 4), sharey=True)
    plotted = 0
    for r in rows:
        path = os.path.join(directory, r["directory"], "profiles.csv")
        if r["status"] != "complete" or not os.path.exists(path) or os.path.getsize(path) == 0:
            continue
        p = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
        if p.size < 2:
            continue
        for ax, q, scale in zip(axes, ("vx", "sigma_yy", "sigma_xy"), (1, 1e-6, 1e-6)):
            # Error bars: the batch-means standard error of each layer's mean, when present.
            err = p[q + "_stderr"] * scale if q + "_stderr" in p.dtype.names else None
            ax.errorbar(p[q] * scale, p["y_over_h"], xerr=err, fmt="o-", ms=2, capsize=1.5, label=label(r))
        plotted += 1
    if plotted:
        axes[0].set_xlabel("vx (m/s)")
        axes[1].set_xlabel("sigma_yy (MPa)")
        axes[2].set_xlabel("sigma_xy (MPa)")
        axes[0].set_ylabel("y / h")
        axes[2].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1))
        save(fig, os.path.join(directory, "profiles_overlay.png"))
    else:
        plt.close(fig)

    ok = [r for r in rows if r["status"] == "complete" and r["mu_mean"] not in ("", None)]
    if ok and varied:
        x_key = varied[0]
        groups = {}
        for r in ok:
            groups.setdefault(tuple(r[k] for k in varied[1:]), []).append(r)
        fig, ax = plt.subplots(figsize=(6, 4))
        for key, group in groups.items():
            try:
                xs = [float(r[x_key]) for r in group]
            except ValueError:
                xs = list(range(len(group)))
            order = np.argsort(xs)
            ax.errorbar(np.array(xs)[order], np.array([float(r["mu_mean"]) for r in group])[order],
                        yerr=np.array([float(r["mu_stderr"] or 0) for r in group])[order], marker="o", capsize=3,
                        label=", ".join(f"{k.split('/')[-1]}={v}" for k, v in zip(varied[1:], key)) or None)
        ax.set_xlabel(x_key)
        ax.set_ylabel("mean friction coefficient (+/- standard error)")
        if len(groups) > 1:
            ax.legend(fontsize=8)
        save(fig, os.path.join(directory, "mu_by_case.png"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_study.py STUDY_OUTPUT_DIR")
    main(sys.argv[1])
