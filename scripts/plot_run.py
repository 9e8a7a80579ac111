#!/usr/bin/python3
"""PNG plots of one shear-cell run directory (Debian's numpy and matplotlib).

    /usr/bin/python3 scripts/plot_run.py OUTPUT_DIR

Writes OUTPUT_DIR/mu.png (friction coefficient against time, steady-state window
and mean), OUTPUT_DIR/power.png (powers of the lower wall, upper wall and
dissipation, running means) and OUTPUT_DIR/profiles.png (x-velocity, solid
fraction, sigma_yy and sigma_xy across the gap), each written atomically.
"""
import json
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)


def running_mean(v, n):
    n = max(1, min(n, len(v)))
    return np.convolve(v, np.ones(n) / n, mode="same")


def main(directory):
    stats = np.atleast_1d(np.genfromtxt(os.path.join(directory, "statistics.csv"), delimiter=",", names=True))
    with open(os.path.join(directory, "summary.json")) as f:
        summary = json.load(f)
    results = summary.get("results", {})
    t_us = stats["time"] * 1e6
    start = results.get("averaging_start", 0.0) * 1e6

    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t_us, stats["mu"], lw=0.5, color="0.6", label="mu(t)")
    ax.plot(t_us, running_mean(stats["mu"], len(t_us) // 50), color="C0", label="running mean")
    if results.get("mu_mean") is not None:
        ax.axvspan(start, t_us[-1], color="C2", alpha=0.1, label="steady state")
        ax.axhline(results["mu_mean"], color="C3", ls="--",
                   label=f"mean {results['mu_mean']:.3f} +/- {results['mu_std']:.3f}")
    ax.set_xlabel("time (us)")
    ax.set_ylabel("friction coefficient mu")
    ax.legend(fontsize=8)
    save(fig, os.path.join(directory, "mu.png"))

    fig, ax = plt.subplots(figsize=(7, 3.5))
    n = len(t_us) // 50
    for name, label in (("power_lower_wall", "lower wall (given)"), ("power_upper_wall", "upper wall"),
                        ("power_dissipated", "dissipated in contacts")):
        ax.plot(t_us, running_mean(stats[name], n), label=label)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("power (W/m), running mean")
    if results.get("power_balance_ratio") is not None:
        ax.set_title(f"dissipated / given by the lower wall in steady state: {results['power_balance_ratio']:.3f}",
                     fontsize=9)
    ax.legend(fontsize=8)
    save(fig, os.path.join(directory, "power.png"))

    path = os.path.join(directory, "profiles.csv")
    if os.path.exists(path) and os.path.getsize(path) > 0:
        p = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
        if p.size > 1:
            fig, axes = plt.subplots(1, 4, figsize=(11, 3.8), sharey=True)
            y = p["y_over_h"]
            columns = [("vx", 1, "vx (m/s)"), ("solid_fraction", 1, "solid fraction"),
                       ("sigma_yy", 1e6, "sigma_yy (MPa)"), ("sigma_xy", 1e6, "sigma_xy (MPa)")]
            for a, (name, scale, label) in zip(axes, columns):
                # Error bars: the batch-means standard error of each layer's mean (profiles.csv).
                err = p[name + "_stderr"] / scale if name + "_stderr" in p.dtype.names else None
                a.errorbar(p[name] / scale, y, xerr=err, fmt="o-", ms=3, capsize=2)
                a.set_xlabel(label)
            axes[0].set_ylabel("y / h (lower wall 0, upper wall 1)")
            for a in axes:
                a.grid(alpha=0.3)
            save(fig, os.path.join(directory, "profiles.png"))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_run.py OUTPUT_DIR")
    main(sys.argv[1])
