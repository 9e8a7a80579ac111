#!/usr/bin/python3
"""The contacts' energy books of NSCD runs, one line each: the run's status, the largest step
work the contacts gave back (max of h P_contacts over the steps) over the drivers' work over
the run (sum of h P_external), the contacts' work summed over the run over the drivers' work,
the fastest body (m/s) and the worst overlap over the smallest radius.

Over a run, frictionless IQS contacts without cohesion take energy. A single step may give
a little back even when solved exactly: at midpoint velocities, a contact that opens at the
step's start while the load closes it does positive work. Much more than converged solves
give back points at the solve (docs/robustness.md, "A wall landing during the shear").

Usage: contact_work.py RUN_DIRECTORY...
"""
import json
import os
import sys

import numpy as np


def books(directory):
    with open(os.path.join(directory, "summary.json")) as f:
        s = json.load(f)
    d = np.genfromtxt(os.path.join(directory, "statistics.csv"), delimiter=",", names=True)
    h = s["time_step"]
    external = np.sum(h * d["power_external"])
    step = h * d["power_contacts"]
    return s["status"], np.max(step) / external, np.sum(step) / external, s["max_body_speed"], \
        s["max_overlap_over_min_radius"]


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("| run | status | largest step's contact work / drivers' work | contacts' work / drivers' work "
          "| fastest body (m/s) | worst overlap / r_min |")
    print("|---|---|---|---|---|---|")
    for run in sys.argv[1:]:
        status, step, total, speed, overlap = books(run)
        print("| %s | %s | %.2g | %.3f | %.0f | %.2f |" % (os.path.basename(os.path.normpath(run)), status, step,
                                                          total, speed, overlap))
