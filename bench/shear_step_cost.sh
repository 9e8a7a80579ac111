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
# twice and resumed for 10 and for 10 + STEPS steps (default 200); the difference of the
# two wall times is the cost of STEPS steps without start-up (reading the checkpoint,
# assembling and factorising the body). Prints, per model, the wall time per step, NLGS
# sweeps per step, contacts, the time per sweep and per contact update, and the fem
# overhead per step and per sweep.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
[ $# -ge 2 ] || { echo "usage: $0 RIGID_RUN_DIR FEM_RUN_DIR [STEPS]" >&2; exit 2; }
for d in "$1" "$2"; do
  [ -f "$d/checkpoint.bin" ] || { echo "$0: $d: no checkpoint.bin" >&2; exit 2; }
done
exec /usr/bin/python3 - "$tribo" "$1" "$2" "${3:-200}" <<'PY'
import csv, os, re, shutil, subprocess, sys, tempfile, time

tribo, dirs, steps = sys.argv[1], {"rigid": sys.argv[2], "fem": sys.argv[3]}, int(sys.argv[4])
warm = 10


def entry(prm, name):
    m = re.search(r"set %s\s*=\s*(\S+)" % re.escape(name), prm)
    return float(m.group(1))


def resume(src, n, tmp, tag):
    dst = os.path.join(tmp, tag)
    shutil.copytree(src, dst)
    prm = open(os.path.join(dst, "parameters.prm")).read()
    h = entry(prm, "Time step")
    step0 = checkpoint_step(os.path.join(dst, "checkpoint.bin"))
    end = (step0 + n) * h
    start = time.perf_counter()
    subprocess.run([tribo, "run", os.path.join(dst, "parameters.prm"), "--resume", dst, "--quiet",
                    "--set", "Simulation/End time=%.17g" % end, "--set", "Output/Field interval=0",
                    "--set", "Output/Plots=false", "--set", "Output/Statistics interval=1",
                    "--set", "Output/Checkpoint interval=0", "--set", "Output/Checkpoint step interval=0"],
                   check=True)
    wall = time.perf_counter() - start
    resumed = int(re.findall(r"resumed at step (\d+)", open(os.path.join(dst, "log.txt")).read())[-1])
    assert resumed == step0, (resumed, step0)
    rows = [r for r in csv.DictReader(open(os.path.join(dst, "statistics.csv")))
            if int(float(r["step"])) > step0 + warm]
    return wall, rows, step0


def checkpoint_step(path):
    """The step a checkpoint was written at: a 0-step resumption logs it."""
    probe = tempfile.mkdtemp()
    try:
        dst = os.path.join(probe, "run")
        shutil.copytree(os.path.dirname(path), dst)
        subprocess.run([tribo, "run", os.path.join(dst, "parameters.prm"), "--resume", dst, "--quiet",
                        "--set", "Simulation/End time=1e-12"], capture_output=True)
        return int(re.findall(r"resumed at step (\d+)", open(os.path.join(dst, "log.txt")).read())[-1])
    finally:
        shutil.rmtree(probe)


tmp = tempfile.mkdtemp()
try:
    cost = {}
    for model, src in dirs.items():
        short, _, step0 = resume(src, warm, tmp, model + "_short")
        long_, rows, _ = resume(src, warm + steps, tmp, model + "_long")
        per_step = (long_ - short) / steps
        sweeps = sum(float(r["nlgs_iterations"]) for r in rows) / len(rows)
        contacts = sum(float(r["n_contacts"]) for r in rows) / len(rows)
        mu = sum(float(r["mu"]) for r in rows) / len(rows)
        cost[model] = (per_step, per_step / sweeps)
        print(f"{model:5s}: from step {step0}, {len(rows)} steps: {per_step * 1e3:8.2f} ms per step, "
              f"{sweeps:7.1f} NLGS sweeps per step, {contacts:6.0f} contacts, "
              f"{per_step / sweeps * 1e6:7.1f} us per sweep, "
              f"{per_step / sweeps / contacts * 1e9:6.1f} ns per contact update, mean mu {mu:.3f}; "
              f"start-up {short - per_step * warm:5.1f} s")
    print(f"fem overhead: {100 * (cost['fem'][0] / cost['rigid'][0] - 1):+.1f} % per step, "
          f"{100 * (cost['fem'][1] / cost['rigid'][1] - 1):+.1f} % per sweep")
finally:
    shutil.rmtree(tmp)
PY
