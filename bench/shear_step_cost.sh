#!/usr/bin/env bash
# Cost of a shear-cell step with the deal.II upper body against the rigid wall, each from
# a checkpoint in steady shear of the same sample (the two models must be compared in
# the same state: from t = 0 the rigid wall is still held by the compaction speed limit
# while the deal.II body has closed the layer).
#
#   bash bench/shear_step_cost.sh RIGID_RUN_DIR FEM_RUN_DIR [STEPS]
#
# Each RUN_DIR is the output directory of a shear run with a checkpoint.bin (e.g. a
# run stopped with SIGTERM, or one with Output/Checkpoint step interval). Each is copied
# and resumed for STEPS steps (default 200); summary.json "timing" gives the wall time
# of those steps and of their phases, without start-up (reading the checkpoint,
# assembling and factorising the body). Prints, per model, the time per step and its
# split (NLGS, detection, the upper body's own predict/finalize), NLGS sweeps per step,
# contacts, the time per sweep and per contact update, and the fem overhead per step and
# per sweep.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
[ $# -ge 2 ] || { echo "usage: $0 RIGID_RUN_DIR FEM_RUN_DIR [STEPS]" >&2; exit 2; }
for d in "$1" "$2"; do
  [ -f "$d/checkpoint.bin" ] || { echo "$0: $d: no checkpoint.bin" >&2; exit 2; }
done
exec /usr/bin/python3 - "$tribo" "$1" "$2" "${3:-200}" <<'PY'
import csv, json, os, re, shutil, subprocess, sys, tempfile

tribo, dirs, steps = sys.argv[1], {"rigid": sys.argv[2], "fem": sys.argv[3]}, int(sys.argv[4])


def resume(src, end, dst):
    shutil.rmtree(dst, ignore_errors=True)
    shutil.copytree(src, dst)
    subprocess.run([tribo, "run", os.path.join(dst, "parameters.prm"), "--resume", dst, "--quiet",
                    "--set", "Simulation/End time=%.17g" % end, "--set", "Output/Field interval=0",
                    "--set", "Output/Plots=false", "--set", "Output/Statistics interval=1",
                    "--set", "Output/Checkpoint interval=0", "--set", "Output/Checkpoint step interval=0"],
                   check=True, capture_output=True)
    resumed = re.findall(r"resumed at step (\d+)", open(os.path.join(dst, "log.txt")).read())[-1]
    return int(resumed), json.load(open(os.path.join(dst, "summary.json")))


tmp = tempfile.mkdtemp()
try:
    cost = {}
    for model, src in dirs.items():
        prm = open(os.path.join(src, "parameters.prm")).read()
        simulation = re.search(r"^subsection Simulation$(.*?)^end$", prm, re.S | re.M).group(1)
        h = float(re.search(r"set Time step\s*=\s*(\S+)", simulation).group(1))
        # A resumption to a time before the checkpoint runs no step: it logs the step.
        step0, _ = resume(src, 1e-12, os.path.join(tmp, model))
        _, s = resume(src, (step0 + steps) * h, os.path.join(tmp, model))
        rows = [r for r in csv.DictReader(open(os.path.join(tmp, model, "statistics.csv")))
                if int(float(r["step"])) > step0]
        t = s["timing"]
        contacts = sum(float(r["n_contacts"]) for r in rows) / len(rows)
        mu = sum(float(r["mu"]) for r in rows) / len(rows)
        per_step, sweeps = t["step_mean_s"], t["solver_iterations_mean"]
        cost[model] = (per_step, per_step / sweeps)
        print(f"{model:5s}: steps {step0}-{step0 + t['steps']}: {per_step * 1e3:8.2f} ms per step "
              f"(NLGS {t['solver_mean_s'] * 1e3:.2f}, detection {t['detection_mean_s'] * 1e3:.2f}, "
              f"upper body {t['boundary_body_mean_s'] * 1e3:.2f}, other {t['other_mean_s'] * 1e3:.2f}), "
              f"{sweeps:7.1f} sweeps per step, {contacts:6.0f} contacts, "
              f"{per_step / sweeps * 1e6:7.1f} us per sweep, "
              f"{t['solver_ns_per_contact_update']:5.1f} ns per contact update, mean mu {mu:.3f}")
    print(f"fem overhead: {100 * (cost['fem'][0] / cost['rigid'][0] - 1):+.1f} % per step, "
          f"{100 * (cost['fem'][1] / cost['rigid'][1] - 1):+.1f} % per sweep")
finally:
    shutil.rmtree(tmp)
PY
