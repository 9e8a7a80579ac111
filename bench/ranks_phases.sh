#!/usr/bin/env bash
# One case on one core against the same case on N MPI ranks (docs/scaling.md, "A case on N
# ranks"): each run one after the other, then the time per step of each phase from the
# summaries (summary.json "timing": detection, the solve and its exchange part, the rest) and
# each phase's efficiency T1 / (N TN), with the sweeps per step and mu +/- its standard error.
# Run it on an otherwise idle machine (two cores: N = 2).
#
#   bash bench/ranks_phases.sh CASE.prm N OUT_DIR [--set "Section/Entry=value" ...]
#
# e.g. the established code's sample tiled four times (16 000 grains, bench/tile_sample.py):
#   bash bench/ranks_phases.sh cases/shear/reference_bench_sample.prm 2 out/phases \
#       --set Solver/Method=apgs --set "Solver/Residual target=1e-3" \
#       --set "Shear cell/Sample file=$PWD/tiled.csv" --set "Shear cell/Length=4e-4" \
#       --set "Simulation/End time=6e-6"
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
[ $# -ge 3 ] || { echo "usage: $0 CASE.prm N OUT_DIR [--set ENTRY=VALUE ...]" >&2; exit 2; }
case_file=$1 ranks=$2 out=$3
shift 3
[ -f "$case_file" ] || { echo "$0: $case_file: no such case file" >&2; exit 2; }
[[ "$ranks" =~ ^[1-9][0-9]*$ ]] || { echo "$0: N = '$ranks': expected a number of ranks" >&2; exit 2; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1} OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
"$tribo" run "$case_file" --output "$out/one" --quiet "$@"
mpirun -np "$ranks" "$tribo" run "$case_file" --output "$out/ranks" --quiet "$@"
exec /usr/bin/python3 - "$out" "$ranks" <<'PY'
import json, os, sys

out, n = sys.argv[1], int(sys.argv[2])
runs = [json.load(open(os.path.join(out, d, "summary.json"))) for d in ("one", "ranks")]
phases = [("step", "step_mean_s"), ("detection", "detection_mean_s"), ("solve", "solver_mean_s"),
          ("of it exchange", "exchange_mean_s"), ("rest", "other_mean_s")]
print(f"| run | steps | " + " | ".join(f"{name}, ms" for name, _ in phases) + " | sweeps per step | mu |")
print("|---|---|" + "---|" * len(phases) + "---|---|")
for label, s in zip(("one core", f"{n} ranks"), runs):
    t, r = s["timing"], s.get("results", {})
    mu = f"{r['mu_mean']:.4f} +/- {r['mu_stderr']:.4f}" if "mu_mean" in r else "-"
    print(f"| {label} | {s['steps']} | " + " | ".join(f"{1e3 * t[key]:.2f}" for _, key in phases) +
          f" | {t['solver_iterations_mean']:.1f} | {mu} |")
one, many = runs[0]["timing"], runs[1]["timing"]
print()
print("T1 / (N TN): " + ", ".join(f"{name} {one[key] / (n * many[key]):.2f}" for name, key in phases
                                     if key != "exchange_mean_s" and many[key] > 0))
PY
