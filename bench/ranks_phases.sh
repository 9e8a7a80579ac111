#!/usr/bin/env bash
# One case on one core against the same case on N MPI ranks (docs/scaling.md, "A case on N
# ranks"): the two runs one after the other, ROUNDS times (default 1), then the time per step
# of each phase from the summaries (summary.json "timing": detection, the solve and its
# exchange part, the rest), each round's efficiency T1 / (N TN) per phase, with the sweeps per
# step and mu +/- its standard error, and over the rounds the step's efficiency's mean and
# standard error (each ratio from two adjacent runs: a machine's drift over a sitting cancels).
# Run it on an otherwise idle machine (two cores: N = 2).
#
#   [ROUNDS=R] bash bench/ranks_phases.sh CASE.prm N OUT_DIR [--set "Section/Entry=value" ...]
#
# e.g. the established code's sample tiled four times (16 000 grains, bench/tile_sample.py):
#   ROUNDS=3 bash bench/ranks_phases.sh cases/shear/reference_bench_sample.prm 2 out/phases \
#       --set Solver/Method=apgs --set "Solver/Residual target=1e-3" \
#       --set "Shear cell/Sample file=$PWD/tiled.csv" --set "Shear cell/Length=4e-4" \
#       --set "Simulation/End time=6e-6"
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
rounds=${ROUNDS:-1}
[ $# -ge 3 ] || { echo "usage: [ROUNDS=R] $0 CASE.prm N OUT_DIR [--set ENTRY=VALUE ...]" >&2; exit 2; }
case_file=$1 ranks=$2 out=$3
shift 3
[ -f "$case_file" ] || { echo "$0: $case_file: no such case file" >&2; exit 2; }
[[ "$ranks" =~ ^[1-9][0-9]*$ ]] || { echo "$0: N = '$ranks': expected a number of ranks" >&2; exit 2; }
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "$0: ROUNDS = '$rounds': expected a number of rounds" >&2; exit 2; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1} OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
for ((r = 1; r <= rounds; ++r)); do
  "$tribo" run "$case_file" --output "$out/one_$r" --quiet "$@"
  mpirun -np "$ranks" "$tribo" run "$case_file" --output "$out/ranks_$r" --quiet "$@"
done
exec /usr/bin/python3 - "$out" "$ranks" "$rounds" <<'PY'
import json, math, os, sys

out, n, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
phases = [("step", "step_mean_s"), ("detection", "detection_mean_s"), ("solve", "solver_mean_s"),
          ("of it exchange", "exchange_mean_s"), ("rest", "other_mean_s")]
print(f"| round | run | steps | " + " | ".join(f"{name}, ms" for name, _ in phases) + " | sweeps per step | mu |")
print("|---|---|---|" + "---|" * len(phases) + "---|---|")
ratios = []
for r in range(1, rounds + 1):
    runs = [json.load(open(os.path.join(out, f"{d}_{r}", "summary.json"))) for d in ("one", "ranks")]
    for label, s in zip(("one core", f"{n} ranks"), runs):
        t, res = s["timing"], s.get("results", {})
        mu = f"{res['mu_mean']:.4f} +/- {res['mu_stderr']:.4f}" if "mu_mean" in res else "-"
        print(f"| {r} | {label} | {s['steps']} | " + " | ".join(f"{1e3 * t[key]:.2f}" for _, key in phases) +
              f" | {t['solver_iterations_mean']:.1f} | {mu} |")
    one, many = runs[0]["timing"], runs[1]["timing"]
    ratios.append(one["step_mean_s"] / (n * many["step_mean_s"]))
    print(f"|   | T1 / (N TN) | | " + " | ".join(f"{one[key] / (n * many[key]):.2f}" if many[key] > 0 and one[key] > 0 else "-"
                                           for _, key in phases) + " | | |")
print()
mean = sum(ratios) / len(ratios)
if len(ratios) > 1:
    se = math.sqrt(sum((x - mean) ** 2 for x in ratios) / (len(ratios) - 1) / len(ratios))
    print(f"step T1 / (N TN) over {len(ratios)} rounds: {mean:.3f} +/- {se:.3f} (rounds: " +
          ", ".join(f"{x:.3f}" for x in ratios) + ")")
else:
    print(f"step T1 / (N TN): {mean:.3f}")
PY
