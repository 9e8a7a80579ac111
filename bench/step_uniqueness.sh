#!/usr/bin/env bash
# Is the friction of one step unique? Each SETTING resumes a copy of a shear run from its
# checkpoint for STEPS steps (default 1) and the script compares, against the first
# SETTING (the reference: give it the tightest solve), what the step leaves:
#   - the grains' velocities after the step: max and rms over the grains of
#     |v - v_ref| (vx, vy and r * spin), over the lower wall's sliding velocity V;
#   - the lower wall's x-force as mu = -F_x / (P L), and its normal force, of the last step;
#   - the upper wall's vertical velocity;
#   - the law residual the step reached and the iterations it took.
# The packings are hyperstatic, so the impulses need not be unique; the velocities are
# (the problem's quadratic form is positive definite in them), and a wall force that every
# tight solve reproduces is a property of the model, not of the method.
#
#   bash bench/step_uniqueness.sh RUN_DIR STEPS "SETTING" ["SETTING" ...]
#
# A SETTING is a space-separated list of Section/Entry=value, as in bench/solver_methods.sh:
#   bash bench/step_uniqueness.sh out/rb 1 \
#       "Solver/Method=interior-point Solver/Residual target=1e-10" \
#       "Solver/Method=apgs Solver/Residual target=1e-8 Solver/Maximum iterations=100000"
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
    """The resumed step; stops at a run that fails."""
    step = resume_copy(tribo, src, dst, end, extra)
    with open(os.path.join(dst, "summary.json")) as f:
        if json.load(f)["status"] != "complete":
            sys.exit(f"{src}: {' '.join(extra)}: the step did not complete (see {dst}/log.txt)")
    return step


def grains(run_dir):
    rows = [r for r in csv.DictReader(open(os.path.join(run_dir, "sample_final.csv")))
            if r["body"] == "grain"]
    return np.array([[float(r["vx"]), float(r["vy"]), float(r["r"]) * float(r["spin"])] for r in rows])


prm = open(os.path.join(src, "parameters.prm")).read()
h = float(re.search(r"^subsection Simulation$.*?set Time step\s*=\s*(\S+)", prm, re.S | re.M).group(1))
first = next(csv.DictReader(open(os.path.join(src, "statistics.csv"))))
if h == 0:  # an adaptive step: the statistics' first row holds it
    h = float(first["time"]) / float(first["step"])
tmp = tempfile.mkdtemp()
try:
    dst = os.path.join(tmp, "run")
    step0 = resume(float(first["time"]), dst, [])
    V = max(abs(float(r["vx"])) for r in csv.DictReader(open(os.path.join(dst, "sample_final.csv")))
            if r["body"] == "lower_wall")
    print(f"checkpoint {src} at step {step0}; {steps} step(s) per setting; velocities against the first setting, over V = {V:g} m/s")
    print("| setting | iterations | law residual | mu | lower wall normal force, N/m | upper wall vy, m/s "
          "| max abs(dv) / V | rms abs(dv) / V |")
    print("|---|---|---|---|---|---|---|---|")
    reference = None
    for setting in settings:
        resume((step0 + steps) * h, dst, entries(setting))
        last = list(csv.DictReader(open(os.path.join(dst, "statistics.csv"))))[-1]
        v = grains(dst)
        if reference is None:
            reference = v
        dv = np.abs(v - reference)
        print(f"| {setting} | {last['solver_iterations']} | {float(last['law_residual']):.2e} "
              f"| {float(last['mu']):.7f} | {float(last['lower_wall_normal_force']):.2f} "
              f"| {float(last['upper_wall_vy']):.6f} | {dv.max() / V:.2e} | {np.sqrt((dv ** 2).mean()) / V:.2e} |",
              flush=True)
finally:
    shutil.rmtree(tmp)
PY
