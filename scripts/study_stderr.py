#!/usr/bin/python3
"""Means with their standard errors for the shear runs of a study (Debian's numpy).

    /usr/bin/python3 scripts/study_stderr.py STUDY_OUTPUT_DIR [FRACTION ...]

For every case directory (case_NNN) with a summary.json, over its averaging window
(summary.json `averaging_start` to the end): mu, the power balance P_diss / P_LB, the
normal force over P L and the face shift of a deformable upper body, each as
`mean +/- stderr`; then vx / V at the layers nearest the given fractions of the gap
(default 0, 0.25, 0.5, 0.75, 1) from profiles.csv with its `vx_stderr`.

Standard error by batch means, the estimator of profiles.csv: the window's rows in
time order cut into B = 10 contiguous batches of (nearly) equal size,
stderr = sqrt(sum_b (m_b - m)^2 / ((B - 1) B)). The ratio P_diss / P_LB is formed per
batch, then averaged the same way. Prints a Markdown table.
"""
import json
import os
import sys

import numpy as np

BATCHES = 10


def batch_means(values, batches=BATCHES):
    """The @p batches batch means of @p values (time order)."""
    return np.array([b.mean() for b in np.array_split(np.asarray(values), batches)])


def mean_stderr(batches):
    return batches.mean(), batches.std(ddof=1) / np.sqrt(len(batches))


def entry(directory, name):
    """The value of `set NAME = value` in the run's parameters.prm (last match)."""
    value = ""
    with open(os.path.join(directory, "parameters.prm")) as f:
        for line in f:
            text = line.split("#")[0].strip()
            if text.startswith("set ") and "=" in text:
                key, v = text[4:].split("=", 1)
                if key.strip() == name:
                    value = v.strip()
    return value


def main(study, fractions):
    print("| case | E (Pa) | D (m) | cohesion (N/m) | steady | mu | P_diss/P_LB | closure | N/(P L) | "
          "face shift (um) | " + " | ".join(f"vx/V at {f:g}" for f in fractions) + " |")
    print("|" + "---|" * (10 + len(fractions)))
    for name in sorted(os.listdir(study)):
        directory = os.path.join(study, name)
        path = os.path.join(directory, "summary.json")
        if not name.startswith("case_") or not os.path.exists(path):
            continue
        with open(path) as f:
            r = json.load(f).get("results") or {}
        if not r.get("sliding") or "averaging_start" not in r:
            continue
        st = np.genfromtxt(os.path.join(directory, "statistics.csv"), delimiter=",", names=True)
        w = st["time"] >= r["averaging_start"]
        mu = mean_stderr(batch_means(st["mu"][w]))
        ratio = mean_stderr(batch_means(st["power_dissipated"][w]) / batch_means(st["power_lower_wall"][w]))
        force = mean_stderr(batch_means(st["lower_wall_normal_force"][w] / st["normal_force"][w]))
        shift = mean_stderr(batch_means(st["upper_body_face_shift"][w] * 1e6))
        V = float(entry(directory, "Sliding velocity"))
        cells = []
        p = np.atleast_1d(np.genfromtxt(os.path.join(directory, "profiles.csv"), delimiter=",", names=True))
        for frac in fractions:
            k = int(np.argmin(np.abs(p["y_over_h"] - frac)))
            cells.append(f"{p['vx'][k] / V:.3f} +/- {p['vx_stderr'][k] / V:.3f}")
        print(f"| {name} | {entry(directory, 'Upper body Young' + chr(39) + 's modulus')} | "
              f"{entry(directory, 'Half-disc diameter')} | {entry(directory, 'Cohesion')} | "
              f"{'yes' if r.get('steady_state_reached') else 'no'} | {mu[0]:.4f} +/- {mu[1]:.4f} | "
              f"{ratio[0]:.3f} +/- {ratio[1]:.3f} | {r.get('power_balance_closure', float('nan')):.3f} | "
              f"{force[0]:.3f} +/- {force[1]:.3f} | {shift[0]:.3f} +/- {shift[1]:.3f} | " +
              " | ".join(cells) + " |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: study_stderr.py STUDY_OUTPUT_DIR [FRACTION ...]")
    main(sys.argv[1], [float(x) for x in sys.argv[2:]] or [0, 0.25, 0.5, 0.75, 1])
