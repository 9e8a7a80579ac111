#!/usr/bin/env bash
# Cost of a shear-cell step with the deal.II upper body against the rigid wall, on the
# same case: runs CASE (default: the paper's sample) for STEPS steps with each model and
# prints the wall time per step, the NLGS sweeps per step and the fem overhead.
#   bash bench/shear_step_cost.sh [CASE.prm] [STEPS] [extra --set arguments...]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
case=${1:-$here/cases/shear/paper.prm}
steps=${2:-300}
shift $(( $# > 2 ? 2 : $# ))
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
h=$(awk -F'= *' '/set Time step/ {print $2; exit}' "$case")
end=$(python3 -c "print($steps * $h)")
for model in rigid fem; do
  "$tribo" run "$case" --output "$out/$model" --quiet --set "Simulation/End time=$end" \
    --set "Output/Field interval=0" --set "Output/Plots=false" --set "Shear cell/Upper body model=$model" "$@"
done
/usr/bin/python3 - "$out" "$steps" <<'PY'
import csv, json, sys
out, steps = sys.argv[1], int(sys.argv[2])
t, per_sweep = {}, {}
for model in ("rigid", "fem"):
    s = json.load(open(f"{out}/{model}/summary.json"))
    rows = list(csv.DictReader(open(f"{out}/{model}/statistics.csv")))
    sweeps = sum(float(r["nlgs_iterations"]) for r in rows) / len(rows)
    t[model] = s["wall_time"] / steps
    contacts = sum(float(r["n_contacts"]) for r in rows) / len(rows)
    per_sweep[model] = t[model] / sweeps
    print(f"{model:5s}: {t[model] * 1e3:8.2f} ms per step, {sweeps:7.1f} NLGS sweeps per step, "
          f"{contacts:7.0f} contacts, {per_sweep[model] * 1e6:7.1f} us per sweep, status {s['status']}")
print(f"fem overhead: {100 * (t['fem'] / t['rigid'] - 1):+.1f} % per step, "
      f"{100 * (per_sweep['fem'] / per_sweep['rigid'] - 1):+.1f} % per sweep "
      "(the two models need different sweep counts: the per-sweep figure is the cost of the body)")
PY
