#!/usr/bin/python3
"""The extremes matrix: short runs of the small shear cell (cases/shear/small.prm, 120
discs), of the collision scene and of the 2D SPH slider at and beyond the edges of their parameters, each
recorded as completed (bounded energy, no NaN, solver converged or not) or stopped early
with the message that names the limit it hit. Writes robustness.csv and robustness.md.

    scripts/robustness.py [--tribo build/bin/tribo] [--output output/robustness]

Every run is 3e-6 s of compaction and 3e-6 s of shear unless its row says otherwise.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHEAR = os.path.join(ROOT, "cases", "shear", "small.prm")
COLLISION = os.path.join(ROOT, "cases", "collision", "iqs.prm")
SPH_QUICK = os.path.join(ROOT, "cases", "sph_slider", "quick.prm")
SHORT = {"Simulation/End time": "6e-6", "Output/Statistics interval": "10", "Output/Plots": "false"}

# (group, label, case, overrides)
MATRIX = [
    ("pressure", "P = 1e4 Pa", SHEAR, {"Shear cell/Pressure": "1e4"}),
    ("pressure", "P = 1e8 Pa (paper)", SHEAR, {}),
    ("pressure", "P = 1e10 Pa", SHEAR, {"Shear cell/Pressure": "1e10"}),
    ("pressure", "P = 1e10 Pa, Overlap recovery 0.1", SHEAR,
     {"Shear cell/Pressure": "1e10", "Contact law/Overlap recovery": "0.1"}),
    ("pressure", "P = 1e10 Pa, NLGS Tolerance 1e-5", SHEAR,
     {"Shear cell/Pressure": "1e10", "Solver/Method": "nlgs", "Solver/Tolerance": "1e-5"}),
    ("velocity", "V = 0.01 m/s", SHEAR, {"Shear cell/Sliding velocity": "0.01"}),
    ("velocity", "V = 50 m/s", SHEAR, {"Shear cell/Sliding velocity": "50"}),
    ("cohesion", "gamma = 1e3 N/m (10 P d)", SHEAR, {"Contact law/Cohesion": "1e3"}),
    ("cohesion", "gamma = 1e5 N/m (1000 P d)", SHEAR, {"Contact law/Cohesion": "1e5"}),
    ("ELAS stiffness", "ELAS k = 1e8", SHEAR, {"Contact law/Law": "ELAS", "Contact law/Stiffness": "1e8"}),
    ("ELAS stiffness", "ELAS k = 1e10 (h = 3 x the contact time)", SHEAR,
     {"Contact law/Law": "ELAS", "Contact law/Stiffness": "1e10"}),
    ("ELAS stiffness", "ELAS k = 1e13", SHEAR, {"Contact law/Law": "ELAS", "Contact law/Stiffness": "1e13"}),
    ("first body E", "fem E = 3e9", SHEAR, {"Shear cell/Upper body model": "fem", "Shear cell/Upper body Young's modulus": "3e9"}),
    ("first body E", "fem E = 1e17 (1e6 x steel)", SHEAR,
     {"Shear cell/Upper body model": "fem", "Shear cell/Upper body Young's modulus": "1e17"}),
    ("first body E", "reduced body (20 modes), E = 3e9", SHEAR,
     {"Shear cell/Upper body model": "reduced", "Shear cell/Upper body Young's modulus": "3e9"}),
    ("first body E", "reduced body (20 modes), E = 1e17", SHEAR,
     {"Shear cell/Upper body model": "reduced", "Shear cell/Upper body Young's modulus": "1e17"}),
    ("SPH damping", "slider, gamma = 1e9 1/s at P = 1e9 Pa (2/gamma = 2e-9 s)", SPH_QUICK,
     {"SPH slider/Gamma": "1e9", "SPH slider/Pressure": "1e9", "Simulation/End time": "4e-4"}),
    ("SPH damping", "slider, gamma = 0 at P = 1e9 Pa", SPH_QUICK,
     {"SPH slider/Gamma": "0", "SPH slider/Pressure": "1e9", "Simulation/End time": "4e-4"}),
    ("time step", "h = 2e-10", SHEAR, {"Simulation/Time step": "2e-10", "Simulation/End time": "4e-6",
                                       "Shear cell/Shear start": "2e-6"}),
    ("time step", "h = 2e-8", SHEAR, {"Simulation/Time step": "2e-8"}),
    ("time step", "h = 2e-8, Most substeps 16", SHEAR, {"Simulation/Time step": "2e-8", "Simulation/Most substeps": "16"}),
    ("time step", "h = 2e-7", SHEAR, {"Simulation/Time step": "2e-7", "Simulation/End time": "2e-5",
                                      "Shear cell/Shear start": "1e-5"}),
    ("time step", "mlp body, h = 2e-9 (c_p h / s = 3.9)", SHEAR,
     {"Shear cell/Upper body model": "mlp", "Shear cell/Upper body Poisson ratio": "0.25",
      "Shear cell/Upper body cell size": "2e-6"}),
    ("sample", "a single disc", SHEAR, {"Shear cell/Number of discs": "1"}),
    ("sample", "two discs", SHEAR, {"Shear cell/Number of discs": "2"}),
    ("sample", "discs placed overlapping by 0.3 r (collision)", COLLISION, {"Collision/Initial gap": "-1.8e-7"}),
    ("sample", "discs placed overlapping by 1.2 r (collision)", COLLISION, {"Collision/Initial gap": "-7.2e-7"}),
]


def run(tribo, out, case, overrides):
    sets = dict(SHORT) if case == SHEAR else {}
    sets.update(overrides)
    args = [tribo, "run", case, "--output", out, "--quiet"]
    for k, v in sets.items():
        args += ["--set", f"{k}={v}"]
    t0 = time.time()
    p = subprocess.run(args, capture_output=True, text=True, timeout=1800)
    wall = time.time() - t0
    row = {"exit": p.returncode, "wall_s": round(wall, 1), "message": "", "steps": "",
           "max_overlap_over_r": "", "nan": "", "non_converged": "", "kinetic_energy_max": ""}
    lines = [l for l in (p.stderr or "").splitlines() if l.strip()]
    if p.returncode != 0 and lines:
        row["message"] = lines[-1]
    summary = os.path.join(out, "summary.json")
    if os.path.exists(summary):
        with open(summary) as f:
            s = json.load(f)
        row["steps"] = f'{s.get("steps", "")} / {s.get("steps_planned", "")}'
        if "max_overlap_over_min_radius" in s:
            row["max_overlap_over_r"] = round(s["max_overlap_over_min_radius"], 3)
        row["non_converged"] = s.get("solver_non_converged_steps", "")
    stats = os.path.join(out, "statistics.csv")
    if os.path.exists(stats):
        with open(stats) as f:
            rows = list(csv.DictReader(f))
        values = [float(v) for r in rows for v in r.values() if v not in ("", None)]
        row["nan"] = any(not math.isfinite(v) for v in values)
        if rows and "kinetic_energy" in rows[0]:
            row["kinetic_energy_max"] = "%.3g" % max(float(r["kinetic_energy"]) for r in rows)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tribo", default=os.path.join(ROOT, "build", "bin", "tribo"))
    ap.add_argument("--output", default=os.path.join(ROOT, "output", "robustness"))
    a = ap.parse_args()
    os.makedirs(a.output, exist_ok=True)
    results = []
    for i, (group, label, case, overrides) in enumerate(MATRIX):
        out = os.path.join(a.output, "run_%02d" % i)
        row = {"group": group, "run": label}
        row.update(run(a.tribo, out, case, overrides))
        results.append(row)
        print("%-16s %-48s exit %d %s" % (group, label, row["exit"], row["message"][:120]), flush=True)
    keys = list(results[0].keys())
    with open(os.path.join(a.output, "robustness.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(results)
    with open(os.path.join(a.output, "robustness.md"), "w") as f:
        f.write("| " + " | ".join(keys) + " |\n|" + "---|" * len(keys) + "\n")
        for r in results:
            f.write("| " + " | ".join(str(r[k]).replace("|", "/") for k in keys) + " |\n")


if __name__ == "__main__":
    main()
