#!/usr/bin/env bash
# NLGS cost against sample size: bench_nlgs on cases/shear/bench.prm scaled to N discs
# (period and wall discs in proportion, so the layer keeps its height and its contact
# network per unit length), for N = 1000, 4000, 16000, 64000 by default.
#
#   bash bench/nlgs_scaling.sh [N ...]
#
# Each sample is compacted for COMPACT steps (default 6000, 1.2e-5 s) at 100 MPa with the NLGS
# tolerance TOL (default 1e-2 Quad: enough for a dense packing, cheap at 64k discs),
# then timed over STEPS steps (default 20) at that tolerance and 200 fixed sweeps.
# Prints one line per N: contacts, ns per contact update (fixed sweeps), time per step
# split into detection and the rest, and memory per disc. The issue's target: ns per
# contact update within 20 % from 1k to 64k discs.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bench=${BENCH_NLGS:-$here/build/bin/bench_nlgs}
compact=${COMPACT:-6000}
steps=${STEPS:-20}
tol=${TOL:-1e-2}
[ $# -gt 0 ] || set -- 1000 4000 16000 64000
printf "%8s %9s %12s %10s %10s %12s %12s %14s\n" discs contacts "ns/update" "ms/step" "sweeps" "detect ns/disc" "rest ns/disc" "bytes/disc"
for n in "$@"; do
  length=$(/usr/bin/python3 -c "print(1e-4 * $n / 3000)")
  walls=$(/usr/bin/python3 -c "print(max(8, round(72 * $n / 3000)))")
  out=$("$bench" "$here/cases/shear/bench.prm" "$compact" "$steps" \
        --set "Shear cell/Number of discs=$n" --set "Shear cell/Length=$length" \
        --set "Shear cell/Wall discs=$walls" --set "Solver/Tolerance=$tol")
  /usr/bin/python3 - "$n" "$out" <<'PY'
import re, sys
n, out = sys.argv[1], sys.argv[2]
grab = lambda pattern: float(re.search(pattern, out).group(1))
print("%8s %9.0f %12.1f %10.2f %10.1f %12.1f %12.1f %14.0f" % (
    n, grab(r"sweeps over (\d+) contacts"), grab(r"\(([\d.]+) ns per update\)"),
    1e3 * grab(r": ([\d.]+) s per step"), grab(r"s per step, ([\d.]+) sweeps"),
    grab(r"per disc: detection ([\d.]+) ns"), grab(r"rest ([\d.]+) ns"), grab(r"memory: (\d+) bytes")))
print("         " + re.search(r"streams .*", out).group(0))
PY
done
