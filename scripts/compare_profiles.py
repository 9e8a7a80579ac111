#!/usr/bin/python3
"""Two shear runs' layer profiles compared layer by layer, with their standard errors.

    /usr/bin/python3 scripts/compare_profiles.py RUN_A RUN_B [--labels A,B] [--plot FILE.png]
        [--control RUN_C RUN_D]

Reads RUN_A/profiles.csv and RUN_B/profiles.csv (docs/outputs.md: the means over each run's
averaging window, with batch-means standard errors) and, for vx, solid_fraction, sigma_xy
and granular_temperature, the difference of each layer in units of the combined error,
    z = (b - a) / sqrt(se_a^2 + se_b^2),
printed as a table: the largest |z|, how many layers lie beyond 2, and the mean z (a
systematic shift shows as a mean far from zero). Layers are matched by index, and both
runs must have the same number of layers across the gap (y / h is the coordinate). With
--plot, an overlay of the four columns against y / h with error bars.

Batch-means errors measure the scatter within one run. Two realisations of one setting
(another seed, another rounding) can differ by more: a run's window may sit in one regime
of the layer for longer than its batches (docs/first_bodies.md, docs/validation.md). With
--control RUN_C RUN_D, such a pair, each column's inflation
    k = max(1, sqrt(mean over the layers of z_CD^2))
is measured (k = 1 when the batch errors cover the realisations' spread, since z is then
about N(0, 1) in each layer), and the comparison of A and B is also given in units of
k times the combined error. Layers are correlated, so k from one pair is a rough figure.
Exit code 2 on a missing or unreadable file or mismatched layers.
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
    parser.add_argument("--control", nargs=2, default=None, metavar="RUN",
                        help="two realisations of one setting: the batch errors' inflation k per column")
    args = parser.parse_args()
    labels = args.labels.split(",") if args.labels else list(args.runs)
    if len(labels) != 2:
        fail(f"--labels {args.labels}: expected two comma-separated labels")
    (path_a, a), (path_b, b) = read(args.runs[0]), read(args.runs[1])
    if len(a) != len(b):
        fail(f"{path_b}: {len(b)} layers, {path_a} has {len(a)}: the runs must have the same layers")
    rows = compare(a, b)
    inflation = None
    if args.control:
        (path_c, c_run), (path_d, d_run) = read(args.control[0]), read(args.control[1])
        for path, table in ((path_c, c_run), (path_d, d_run)):
            if len(table) != len(a):
                fail(f"{path}: {len(table)} layers, {path_a} has {len(a)}: the runs must have the same layers")
        inflation = {c: max(1.0, float(np.sqrt(np.mean(z ** 2)))) if z.size else 1.0
                     for c, (_, _, _, z) in compare(c_run, d_run).items()}
        print(f"control: {args.control[1]} against {args.control[0]}; "
              "k = max(1, root mean square of their z over the layers)")
    print(f"{labels[1]} against {labels[0]}, {len(a)} layers; z = difference / combined standard error")
    if inflation is None:
        print("| column | max abs z | layers beyond 2 | mean z |")
        print("|---|---|---|---|")
        for c, (zmax, beyond, zmean, _) in rows.items():
            print(f"| {c} | {zmax:.2f} | {beyond} | {zmean:+.2f} |")
    else:
        print("| column | max abs z | layers beyond 2 | mean z | k | max abs z / k | layers beyond 2 k | mean z / k |")
        print("|---|---|---|---|---|---|---|---|")
        for c, (zmax, beyond, zmean, z) in rows.items():
            k = inflation[c]
            print(f"| {c} | {zmax:.2f} | {beyond} | {zmean:+.2f} | {k:.2f} | {zmax / k:.2f} | "
                  f"{int((np.abs(z) > 2 * k).sum())} | {zmean / k:+.2f} |")
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
