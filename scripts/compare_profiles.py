#!/usr/bin/python3
"""Two shear runs' layer profiles compared layer by layer, with their standard errors.

    /usr/bin/python3 scripts/compare_profiles.py RUN_A RUN_B [--labels A,B] [--plot FILE.png]

Reads RUN_A/profiles.csv and RUN_B/profiles.csv (docs/outputs.md: the means over each run's
averaging window, with batch-means standard errors) and, for vx, solid_fraction, sigma_xy
and granular_temperature, the difference of each layer in units of the combined error,
    z = (b - a) / sqrt(se_a^2 + se_b^2),
printed as a table: the largest |z|, how many layers lie beyond 2, and the mean z (a
systematic shift shows as a mean far from zero). Layers are matched by index, and both
runs must have the same number of layers across the gap (y / h is the coordinate). With
--plot, an overlay of the four columns against y / h with error bars. Exit code 2 on a
missing or unreadable file or mismatched layers.
"""
import argparse
import os
import sys

import numpy as np

COLUMNS = ("vx", "solid_fraction", "sigma_xy", "granular_temperature")


def fail(message):
    """Print @p message on stderr and exit with code 2 (bad input)."""
    sys.stderr.write(message + "\n")
    sys.exit(2)


def read(run):
    path = os.path.join(run, "profiles.csv")
    try:
        table = np.genfromtxt(path, delimiter=",", names=True)
    except OSError as error:
        fail(f"{path}: cannot read ({error})")
    names = table.dtype.names or ()
    missing = [c for c in ("y_over_h",) + COLUMNS + tuple(c + "_stderr" for c in COLUMNS) if c not in names]
    if missing:
        fail(f"{path}: expected the columns {', '.join(missing)} (docs/outputs.md, profiles.csv)")
    return path, np.atleast_1d(table)


def compare(a, b):
    """Per column: (max |z|, layers with |z| > 2, mean z, z per layer)."""
    rows = {}
    for c in COLUMNS:
        error = np.sqrt(a[c + "_stderr"] ** 2 + b[c + "_stderr"] ** 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = (b[c] - a[c]) / error
        z = z[np.isfinite(z)]
        rows[c] = (np.abs(z).max() if z.size else float("nan"), int((np.abs(z) > 2).sum()),
                   z.mean() if z.size else float("nan"), z)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs=2, metavar="RUN")
    parser.add_argument("--labels", default=None, help="two comma-separated labels (default: the directories)")
    parser.add_argument("--plot", default=None, help="write an overlay figure here")
    args = parser.parse_args()
    labels = args.labels.split(",") if args.labels else list(args.runs)
    if len(labels) != 2:
        fail(f"--labels {args.labels}: expected two comma-separated labels")
    (path_a, a), (path_b, b) = read(args.runs[0]), read(args.runs[1])
    if len(a) != len(b):
        fail(f"{path_b}: {len(b)} layers, {path_a} has {len(a)}: the runs must have the same layers")
    rows = compare(a, b)
    print(f"{labels[1]} against {labels[0]}, {len(a)} layers; z = difference / combined standard error")
    print("| column | max abs z | layers beyond 2 | mean z |")
    print("|---|---|---|---|")
    for c, (zmax, beyond, zmean, _) in rows.items():
        print(f"| {c} | {zmax:.2f} | {beyond} | {zmean:+.2f} |")
    if args.plot:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        from plotting import plt, save  # scripts/plotting.py
        fig, axes = plt.subplots(1, len(COLUMNS), figsize=(4 * len(COLUMNS), 4), sharey=True)
        for ax, c in zip(axes, COLUMNS):
            for table, label in ((a, labels[0]), (b, labels[1])):
                ax.errorbar(table[c], table["y_over_h"], xerr=table[c + "_stderr"], marker="o", ms=3,
                            capsize=2, label=label)
            ax.set_xlabel(c)
        axes[0].set_ylabel("y / h")
        axes[0].legend()
        save(fig, args.plot)


if __name__ == "__main__":
    main()
