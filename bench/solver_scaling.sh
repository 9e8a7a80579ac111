#!/usr/bin/env bash
# Contact solvers against sample size: the established code's benchmark cell
# (cases/shear/reference_bench.prm) scaled to N grains, either at fixed layer thickness
# (period and wall discs in proportion to N: `width`) or at fixed period (the layer
# N / 3800 times as thick: `thickness`). Each sample is compacted (1e-5 s, 1000 steps; a
# thicker layer for N / 3800 times as long, since it takes longer to collapse) by APGD to a
# law residual of 1e-3 on both cores, the cheapest way to a dense packing (samples made
# before 2026-11-26 were compacted by MPRGP at 1.5e-3; at 64 000 grains the compaction
# collapses past a radius: that sample is the 16 000-grain one tiled four times,
# bench/tile_sample.py, docs/performance.md),
# sheared for SHEAR steps (default 500) to a checkpoint, then each SETTING resumes it for
# STEPS steps (default 50) through bench/solver_methods.sh, which prints the table.
#
#   bash bench/solver_scaling.sh width|thickness N [N ...] -- SETTING [SETTING ...]
#
# e.g. bash bench/solver_scaling.sh width 1000 4000 16000 -- "Solver/Method=nlgs" \
#          "Solver/Method=mprgp Solver/Residual target=1.5e-3"
# Samples are kept in ${SCALING_DIR:-/tmp/tribo-solver-scaling}/<mode>-<N>; an existing
# checkpoint is reused. With FRICTION=MU the samples have Coulomb friction MU between grains
# and at the walls from the start (a resumed run may not change the contact law), are made by
# APGS (which solves friction) instead of APGD, and are kept in <mode>-<N>-mu<MU>.
# Run it on an otherwise idle machine.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tribo=${TRIBO:-$here/build/bin/tribo}
mode=${1:-}; shift || true
[ "$mode" = width ] || [ "$mode" = thickness ] || { echo "usage: $0 width|thickness N [N ...] -- SETTING [SETTING ...]" >&2; exit 2; }
sizes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do sizes+=("$1"); shift; done
[ $# -gt 1 ] || { echo "$0: no SETTING after --" >&2; exit 2; }
shift
shear=${SHEAR:-500}
steps=${STEPS:-50}
root=${SCALING_DIR:-/tmp/tribo-solver-scaling}
mkdir -p "$root"
for n in "${sizes[@]}"; do
  if [ "$mode" = width ]; then
    length=$(/usr/bin/python3 -c "print(1e-4 * $n / 3800)")
    walls=$(/usr/bin/python3 -c "print(max(8, round(100 * $n / 3800)))")
  else
    length=1e-4
    walls=100
  fi
  compaction=1000  # steps of 1e-8 s
  [ "$mode" = thickness ] && compaction=$(/usr/bin/python3 -c "print(max(1000, round(1000 * $n / 3800)))")
  dir="$root/$mode-$n"
  law=(--set "Solver/Method=apgd")
  if [ -n "${FRICTION:-}" ]; then
    dir="$dir-mu$FRICTION"
    law=(--set "Contact law/Friction coefficient=$FRICTION" --set "Solver/Method=apgs")
  fi
  if [ ! -f "$dir/checkpoint.bin" ]; then
    rm -rf "$dir"
    end=$(/usr/bin/python3 -c "print(($compaction + $shear + 3000) * 1e-8)")  # stopped at the checkpoint
    "$tribo" run "$here/cases/shear/reference_bench.prm" --output "$dir" --quiet \
      --set "Shear cell/Number of discs=$n" --set "Shear cell/Length=$length" \
      --set "Shear cell/Wall discs=$walls" --set "Shear cell/Shear start=$(/usr/bin/python3 -c "print($compaction * 1e-8)")" \
      --set "Simulation/End time=$end" "${law[@]}" \
      --set "Solver/Residual target=1e-3" --set "Solver/Threads=2" \
      --set "Output/Checkpoint step interval=$((compaction + shear))" --set "Output/Plots=false" &
    pid=$!
    while [ ! -f "$dir/checkpoint.bin" ] && kill -0 "$pid" 2>/dev/null; do sleep 0.2; done
    kill -TERM "$pid" 2>/dev/null || true
    wait "$pid" || true
    [ -f "$dir/checkpoint.bin" ] || { echo "$0: $dir: no checkpoint (see its log.txt)" >&2; exit 1; }
  fi
  echo "## $mode, $n grains (period $length m, $walls wall discs${FRICTION:+, friction $FRICTION})"
  bash "$here/bench/solver_methods.sh" "$dir" "$steps" "$@"
done
