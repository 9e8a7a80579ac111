#!/bin/bash
# Cost of the upper-body models at h = 2e-9 s (docs/first_bodies.md, "Cost"): short runs
# of the 120-disc cell (1000 steps) and of the default case (50 steps) with each model,
# one after the other; prints the log's last line (per-step times). Run it on an idle
# machine.
#   bash bench/first_body_models.sh [OUTPUT_DIR]     (TRIBO=binary to time another build)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
tribo="${TRIBO:-$root/build/bin/tribo}"
out="${1:-$root/output/bench_first_body_models}"
mkdir -p "$out"
common=(--quiet --set "Shear cell/Upper body Poisson ratio=0.25" --set "Output/Plots=false")
for m in rigid fem mlp sph; do
  rm -rf "$out/small_$m"
  "$tribo" run "$root/cases/shear/small.prm" --output "$out/small_$m" "${common[@]}" \
    --set "Shear cell/Upper body model=$m" --set "Simulation/End time=2e-6" \
    --set "Shear cell/Upper body cell size=1.5e-6"
  echo "small $m: $(grep 'status complete' "$out/small_$m/log.txt")"
done
for m in fem mlp sph; do
  rm -rf "$out/default_$m"
  "$tribo" run "$root/cases/shear/default.prm" --output "$out/default_$m" "${common[@]}" \
    --set "Shear cell/Upper body model=$m" --set "Simulation/End time=1e-7"
  echo "default $m: $(grep 'status complete' "$out/default_$m/log.txt")"
  grep 'upper body:' "$out/default_$m/log.txt"
done
