#!/usr/bin/env bash
# Contact solvers side by side from one checkpoint: each setting resumes a copy of the run
# for STEPS steps and prints its time per step (summary.json "timing": the steps alone,
# no start-up), the solver's and the contact detection's shares, iterations per step (NLGS sweeps, predictor sweeps
# plus MPRGP products), CHOLMOD factorisations per step, the law residual reached (mean
# and max over the steps, docs/laws.md), the worst overlap over the smallest radius, and
# mean mu +/- its batch-means standard error (10 contiguous batches, the estimator of
# scripts/study_stderr.py; meaningful over several hundred steps). Run it on an otherwise idle machine; settings are timed in turn, in one sitting.
#
#   bash bench/solver_methods.sh RUN_DIR STEPS "SETTING" ["SETTING" ...]
#
# RUN_DIR: a shear run with a checkpoint.bin (Output/Checkpoint step interval); a SETTING
# is a space-separated list of Section/Entry=value, e.g.
#   bash bench/solver_methods.sh out/rb 100 "Solver/Method=nlgs" \
#       "Solver/Method=mprgp Solver/Residual target=1e-3 Solver/Threads=2"
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
[ $# -ge 3 ] || { echo "usage: $0 RUN_DIR STEPS SETTING [SETTING ...]" >&2; exit 2; }
[ -f "$1/checkpoint.bin" ] || { echo "$0: $1: no checkpoint.bin" >&2; exit 2; }
exec /usr/bin/python3 - "$here/bench" "$tribo" "$@" <<'PY'
import csv, json, os, re, shutil, sys, tempfile

import numpy as np

sys.path.insert(0, sys.argv[1])
from checkpoint_copies import entries, resume as resume_copy  # noqa: E402

tribo, src, steps, settings = sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5:]


def resume(end, dst, extra):
    """The resumed step and the summary (a failed run is reported, not fatal)."""
    step = resume_copy(tribo, src, dst, end, extra)
    return step, json.load(open(os.path.join(dst, "summary.json")))


prm = open(os.path.join(src, "parameters.prm")).read()
simulation = re.search(r"^subsection Simulation$(.*?)^end$", prm, re.S | re.M).group(1)
h = float(re.search(r"set Time step\s*=\s*(\S+)", simulation).group(1))
r_min = None
shear = re.search(r"^subsection Shear cell$(.*?)^end$", prm, re.S | re.M)
shear = shear.group(1) if shear else ""
m = re.search(r"set Mean diameter\s*=\s*(\S+)", shear)
spread = re.search(r"set Diameter spread\s*=\s*(\S+)", shear)
if m and spread:
    r_min = float(m.group(1)) * (1 - float(spread.group(1))) / 2
tmp = tempfile.mkdtemp()
try:
    dst = os.path.join(tmp, "run")
    # An End time at the run's first step is before its checkpoint and after any Initial
    # state's t0: the resume logs the checkpoint's step and runs nothing.
    first = next(csv.DictReader(open(os.path.join(src, "statistics.csv"))))
    step0, at_checkpoint = resume(float(first["time"]), dst, [])
    print(f"checkpoint {src} at step {step0}, {steps} steps per setting")
    print("| setting | ms per step | solver ms | detection ms | iterations per step | factorisations per step "
          "| law residual mean / max | worst overlap / r_min | mu |")
    print("|---|---|---|---|---|---|---|---|---|")
    for setting in settings:
        _, s = resume((step0 + steps) * h, dst, entries(setting))
        rows = [r for r in csv.DictReader(open(os.path.join(dst, "statistics.csv")))
                if int(float(r["step"])) > step0]
        if s["status"] != "complete":
            print(f"| {setting} | {s['status']} after {len(rows)} steps: {s.get('error', '')[:160]} |",
                  flush=True)
            continue
        t = s["timing"]
        # summary.json's mean is over every step of the run, the checkpoint's included: take
        # away the factorisations the run had made by its checkpoint.
        factorizations = (s.get("factorizations_mean", 0) * s["steps"]
                          - at_checkpoint.get("factorizations_mean", 0) * at_checkpoint["steps"]) / len(rows)
        lr = [float(r["law_residual"]) for r in rows]
        overlap = max(float(r["max_overlap"]) for r in rows)
        mu = np.array([float(r["mu"]) for r in rows])
        batches = np.array([b.mean() for b in np.array_split(mu, 10)])
        mu_stderr = batches.std(ddof=1) / np.sqrt(len(batches))
        print(f"| {setting} | {t['step_mean_s'] * 1e3:.1f} | {t['solver_mean_s'] * 1e3:.1f} | {t['detection_mean_s'] * 1e3:.1f} "
              f"| {t['solver_iterations_mean']:.1f} | {factorizations:.1f} "
              f"| {sum(lr) / len(lr):.2e} / {max(lr):.2e} "
              f"| {overlap / r_min if r_min else float('nan'):.2f} | {mu.mean():.4f} +/- {mu_stderr:.4f} |", flush=True)
finally:
    shutil.rmtree(tmp)
PY
