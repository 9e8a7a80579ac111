#!/usr/bin/env python3
"""Proof that a refactoring changed no result: a short run of every scene and first-body
model, from the shipped cases, gives a statistics.csv identical, byte for byte, to the
one stored in tests/unchanged/ (issue 24: "behaviour unchanged").

    /usr/bin/python3 scripts/check_unchanged.py            # compare; exit 1 on a difference
    /usr/bin/python3 scripts/check_unchanged.py --record   # (re)write the stored files
    /usr/bin/python3 scripts/check_unchanged.py NAME ...   # only these runs
    /usr/bin/python3 scripts/check_unchanged.py --without sph,mlp   # modules not built

Record only after a change meant to change results, and say so in its commit. The stored
files hold this machine's bits (same compiler, same libraries): a different compiler or
deal.II build may differ in the last digits, which this script then reports as a
difference (the first row and column that differ, both values).
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STORED = os.path.join(HERE, "tests", "unchanged")

# name: (case file, --set entries). Short enough for the whole list to take about a minute;
# every shear run reaches its shear phase.
RUNS = {
    "collision-iqs": ("cases/collision/iqs.prm", ["Output/Statistics interval=100"]),
    "collision-elas": ("cases/collision/elas.prm", ["Output/Statistics interval=10"]),
    "shear-rigid": ("cases/shear/small.prm",
                    ["Simulation/End time=3.4e-6", "Output/Statistics interval=5"]),
    "shear-default": ("cases/shear/default.prm",
                      ["Simulation/End time=4e-7", "Shear cell/Shear start=3e-7",
                       "Output/Plots=false", "Output/Field interval=0",
                       "Output/Statistics interval=1"]),
}
# The deformable and particle upper bodies on the 120-disc cell of
# cases/shear/first_bodies.prm (its fixed entries), 300 steps, shear from step 200.
for model in ("fem", "reduced", "sph", "mlp"):
    RUNS["shear-" + model] = ("cases/shear/small.prm", [
        "Shear cell/Upper body model=" + model, "Simulation/Time step=3.5e-10",
        "Simulation/End time=1.05e-7", "Shear cell/Pressure ramp time=3.5e-8",
        "Shear cell/Shear start=7e-8", "Shear cell/Upper body Poisson ratio=0.25",
        "Shear cell/Upper body cell size=1.5e-6", "Output/Statistics interval=5"])
RUNS.update({
    "sph-slider": ("cases/sph_slider/quick.prm", ["Simulation/End time=1.1e-4",
                                                  "SPH slider/Field interval=0"]),
    "sph-plate": ("cases/sph_slider/plate.prm", ["Simulation/End time=2e-5",
                                                  "SPH plate/Statistics interval=5e-7"]),
    "mlp-compression": ("cases/mlp/compression.prm", ["Simulation/End time=2e-7"]),
    "mlp-beams": ("cases/mlp/beams.prm", ["Simulation/End time=3e-7"]),
    "mlp-ordering-hex": ("cases/mlp/ordering_hex.prm", ["Simulation/End time=3e-7",
                                                        "MLP/Statistics interval=20"]),
    "mlp-ordering-square": ("cases/mlp/ordering_square.prm", ["Simulation/End time=3e-7",
                                                              "MLP/Statistics interval=20"]),
    "mlp-wave": ("cases/mlp/wave.prm", ["Simulation/End time=2e-8"]),
})


# The optional module each run needs (CMake's TRIBO_WITH_*); the others need none.
MODULE = {"shear-fem": "fem", "shear-reduced": "fem", "shear-sph": "sph", "shear-mlp": "mlp",
          "sph-slider": "sph", "sph-plate": "sph"}
MODULE.update({name: "mlp" for name in RUNS if name.startswith("mlp-")})


def run(name, tribo, workdir):
    """Run @p name; return its statistics.csv text."""
    case, settings = RUNS[name]
    out = os.path.join(workdir, name)
    args = [tribo, "run", os.path.join(HERE, case), "--output", out, "--quiet"]
    for s in settings:
        args += ["--set", s]
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{name}: tribo exited with {done.returncode}:\n{done.stderr}")
    with open(os.path.join(out, "statistics.csv")) as f:
        return f.read()


def first_difference(stored, now):
    """The first row and column where two CSV texts differ, as a sentence."""
    a, b = stored.splitlines(), now.splitlines()
    header = a[0].split(",") if a else []
    for row, (x, y) in enumerate(zip(a, b)):
        if x != y:
            for col, (u, v) in enumerate(zip(x.split(","), y.split(","))):
                if u != v:
                    label = header[col] if col < len(header) else f"column {col}"
                    return f"line {row + 1}, {label}: stored {u}, now {v}"
            return f"line {row + 1}: stored '{x}', now '{y}'"
    return f"{len(a)} stored lines, {len(b)} now"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="runs to check (default: all): " + ", ".join(RUNS))
    parser.add_argument("--record", action="store_true", help="write the stored files")
    parser.add_argument("--tribo", default=os.path.join(HERE, "build", "bin", "tribo"))
    parser.add_argument("--without", default="", help="comma-separated modules not built: fem, sph, mlp")
    args = parser.parse_args()
    unknown = [n for n in args.names if n not in RUNS]
    if unknown:
        raise SystemExit(f"unknown run(s) {', '.join(unknown)}; expected some of: {', '.join(RUNS)}")
    without = {m for m in args.without.split(",") if m}
    if without - {"fem", "sph", "mlp"}:
        raise SystemExit(f"--without {args.without}: expected some of fem, sph, mlp")
    workdir = tempfile.mkdtemp(prefix="tribo-unchanged-")
    differ = 0
    try:
        for name in args.names or [n for n in RUNS if MODULE.get(n) not in without]:
            now = run(name, args.tribo, workdir)
            path = os.path.join(STORED, name + ".csv")
            if args.record:
                os.makedirs(STORED, exist_ok=True)
                with open(path, "w") as f:
                    f.write(now)
                print(f"{name}: recorded {len(now.splitlines()) - 1} rows")
                continue
            if not os.path.exists(path):
                print(f"{name}: no stored file {os.path.relpath(path, HERE)} (run with --record)")
                differ += 1
                continue
            with open(path) as f:
                stored = f.read()
            if stored == now:
                print(f"{name}: identical ({len(now.splitlines()) - 1} rows)")
            else:
                print(f"{name}: DIFFERS, {first_difference(stored, now)}")
                differ += 1
    finally:
        shutil.rmtree(workdir)
    if differ:
        print(f"{differ} run(s) differ from tests/unchanged/", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
