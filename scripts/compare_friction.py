#!/usr/bin/python3
"""Shear runs' friction and load over one time window, with batch-means standard errors at
two batch counts, and every pair's difference in combined errors.

    /usr/bin/python3 scripts/compare_friction.py T0_US T1_US RUN [RUN ...]

Reads each RUN/statistics.csv (docs/outputs.md) and takes the rows with T0 <= time <= T1
(microseconds). For each run: mu and the load N / (P L) (the lower wall's normal force
over the imposed one, lower_wall_normal_force / normal_force), each as mean +/- the
batch-means standard error of scripts/study_stderr.py with 10 batches, and mu's error with
4 batches too (longer batches see slower fluctuations, such as the shear cell's switching
between a plug and a sheared layer: docs/first_bodies.md); the largest max_overlap in the
window. Then for every pair of runs the difference of mu, d = mu_b - mu_a, with
e = sqrt(se_a^2 + se_b^2) and d / e for both batch counts. Prints Markdown tables.
Exit code 2 on a missing or unreadable file, a missing column, or a window that holds
fewer than 4 rows of a run (naming the run and the times it holds).
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_stderr import batch_means, mean_stderr  # noqa: E402

COLUMNS = ("time", "mu", "normal_force", "lower_wall_normal_force", "max_overlap")


def fail(message):
    """Print @p message on stderr and exit with code 2 (bad input)."""
    sys.stderr.write(message + "\n")
    sys.exit(2)


def window(run, t0, t1):
    """The rows of RUN/statistics.csv with t0 <= time <= t1 (s), as a structured array."""
    path = os.path.join(run, "statistics.csv")
    try:
        table = np.genfromtxt(path, delimiter=",", names=True)
    except (OSError, ValueError) as error:
        fail(f"{path}: cannot read ({error})")
    names = table.dtype.names or ()
    missing = [c for c in COLUMNS if c not in names]
    if missing:
        fail(f"{path}: expected the columns {', '.join(missing)} (docs/outputs.md, statistics.csv)")
    rows = table[(table["time"] >= t0) & (table["time"] <= t1)]
    if len(rows) < 4:
        fail(f"{path}: {len(rows)} rows in {t0 * 1e6:g}-{t1 * 1e6:g} us (the run holds "
             f"{table['time'][0] * 1e6:g}-{table['time'][-1] * 1e6:g} us); at least 4 are needed")
    return rows


def main():
    if len(sys.argv) < 4:
        fail("usage: compare_friction.py T0_US T1_US RUN [RUN ...]")
    try:
        t0, t1 = float(sys.argv[1]) * 1e-6, float(sys.argv[2]) * 1e-6
    except ValueError:
        fail(f"the window must be two times in microseconds, got '{sys.argv[1]}' and '{sys.argv[2]}'")
    runs = sys.argv[3:]
    mu = {}
    print("| run | rows, us | mu +/- se (10 batches) | se (4 batches) | N / (P L) | max overlap, m |")
    print("|---|---|---|---|---|---|")
    for run in runs:
        rows = window(run, t0, t1)
        m10 = mean_stderr(batch_means(rows["mu"], 10))
        m4 = mean_stderr(batch_means(rows["mu"], 4))
        load = mean_stderr(batch_means(rows["lower_wall_normal_force"] / rows["normal_force"], 10))
        mu[run] = (m10[0], m10[1], m4[1])
        print(f"| {run} | {len(rows)}, {rows['time'][0] * 1e6:.2f}-{rows['time'][-1] * 1e6:.2f} | "
              f"{m10[0]:.4f} +/- {m10[1]:.4f} | {m4[1]:.4f} | {load[0]:.4f} +/- {load[1]:.4f} | "
              f"{rows['max_overlap'].max():.3e} |")
    if len(runs) > 1:
        print()
        print("| b - a | mu_b - mu_a | combined error, 10 / 4 batches | errors, 10 / 4 batches |")
        print("|---|---|---|---|")
        for i, a in enumerate(runs):
            for b in runs[i + 1:]:
                d = mu[b][0] - mu[a][0]
                e10, e4 = np.hypot(mu[a][1], mu[b][1]), np.hypot(mu[a][2], mu[b][2])
                print(f"| {b} - {a} | {d:+.4f} | {e10:.4f} / {e4:.4f} | {d / e10:+.1f} / {d / e4:+.1f} |")


if __name__ == "__main__":
    main()
