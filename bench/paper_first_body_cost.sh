#!/bin/bash
# Cost of the fem and sph upper bodies at the paper's size in the shear cell
# (docs/first_bodies.md, "Cost"): cases/shear/deformable_e1.prm (3820 grains, L = 1e-4 m,
# h = 2e-9 s) with APGS at 1e-3, shear from 3 us; each model's state at step 2000 (4 us,
# the body on the layer) is kept once (the run is killed after its checkpoint), then each
# round resumes it for 250 steps and prints the log's per-step line. Run it on an idle
# machine; OLD=binary adds a round of that binary's sph body (for a ratio in one sitting).
#   bash bench/paper_first_body_cost.sh [OUTPUT_DIR] [ROUNDS]   (TRIBO=binary, OLD=binary)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
tribo="${TRIBO:-$root/build/bin/tribo}"
out="${1:-$root/output/bench_paper_first_body_cost}"
rounds="${2:-3}"
mkdir -p "$out"
for m in fem sph; do
  if [ ! -f "$out/state_$m/checkpoint.bin" ]; then
    rm -rf "$out/state_$m"
    "$tribo" run "$root/cases/shear/deformable_e1.prm" --output "$out/state_$m" --quiet \
      --set "Shear cell/Upper body model=$m" --set "Shear cell/Upper body Poisson ratio=0.25" \
      --set "Shear cell/Half-disc diameter=1.2e-6" --set "Solver/Residual target=1e-3" \
      --set "Output/Statistics interval=10" --set "Output/Field interval=0" --set "Output/Plots=false" \
      --set "Shear cell/Shear start=3e-6" --set "Simulation/End time=1e-5" \
      --set "Output/Checkpoint step interval=2000" > "$out/state_$m.out" 2>&1 &
    pid=$!
    while [ ! -f "$out/state_$m/checkpoint.bin" ]; do sleep 1; done
    sleep 2   # the checkpoint is written atomically; the run goes on past it
    kill -9 "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
  fi
done
resume() { # label binary model
  rm -rf "$out/run_$1"
  cp -r "$out/state_$3" "$out/run_$1"
  "$2" run "$out/run_$1/parameters.prm" --resume "$out/run_$1" --quiet --set "Simulation/End time=4.5e-6" \
    > "$out/run_$1.out" 2>&1
  echo "$1: $(grep 'status complete' "$out/run_$1/log.txt" | sed 's/.*per step/per step/')"
}
for r in $(seq "$rounds"); do
  resume "fem$r" "$tribo" fem
  resume "sph$r" "$tribo" sph
  if [ -n "${OLD:-}" ] && [ "$r" = 1 ]; then resume "sph_old" "$OLD" sph; fi
done
