#!/usr/bin/python3
"""Proof that a refactoring changed no result: a short run of every scene and first-body
model, from the shipped cases, gives a statistics.csv identical, byte for byte, to the
one stored in tests/unchanged/ (issue 24: "behaviour unchanged").

    /usr/bin/python3 scripts/check_unchanged.py            # compare; exit 1 on a difference
    /usr/bin/python3 scripts/check_unchanged.py --record   # (re)write the stored files
    /usr/bin/python3 scripts/check_unchanged.py NAME ...   # only these runs
    /usr/bin/python3 scripts/check_unchanged.py --without sph,mlp   # modules not built

Record only after a change meant to change results, and say so in its commit. The stored
files hold the recording machine's bits (tests/unchanged/MACHINE: its processor and vector
instructions, its compiler). On that machine the comparison is byte for byte. On another
one the libraries' vector kernels round differently (2026-11-26: a machine with AVX-512
changed shear-reduced's power_external in its 17th digit, and the chaotic run carried it
to 3.3e-7 of upper_body_face_shift's scale): there every column must stay within
OTHER_MACHINE_TOLERANCE of its largest magnitude over the run, and the script says which
comparison it made. A difference is reported with its first row and column and both values.
"""
import argparse
import io
import os
import platform
import shutil
import subprocess
import sys
import tempfile

import numpy as np

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


OTHER_MACHINE_TOLERANCE = 1e-6
MACHINE_FILE = os.path.join(STORED, "MACHINE")


def machine():
    """This machine as far as its round-off goes: processor, vector instructions, compiler."""
    model, flags = platform.processor(), set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name":
                    model = value.strip()
                elif key.strip() == "flags":
                    flags = {x for x in value.split() if x.startswith(("avx", "fma", "sse4"))}
    except OSError:
        pass
    compiler = subprocess.run(["c++", "-dumpfullversion"], capture_output=True, text=True).stdout.strip()
    return f"{model}; {' '.join(sorted(flags))}; c++ {compiler}"


def differs_beyond(stored, now, tolerance):
    """None if every column of two CSV texts agrees within @p tolerance of its largest
    magnitude, else the first row and column that does not, as a sentence."""
    a = np.genfromtxt(io.StringIO(stored), delimiter=",", names=True)
    b = np.genfromtxt(io.StringIO(now), delimiter=",", names=True)
    if a.shape != b.shape or a.dtype.names != b.dtype.names:
        return f"{len(stored.splitlines())} stored lines, {len(now.splitlines())} now (or other columns)"
    for name in a.dtype.names:
        scale = max(np.max(np.abs(a[name])), np.max(np.abs(b[name])))
        off = np.flatnonzero(np.abs(a[name] - b[name]) > tolerance * scale)
        if off.size:
            row = off[0]
            return (f"line {row + 2}, {name}: stored {a[name][row]!r}, now {b[name][row]!r} "
                    f"(more than {tolerance:g} of the column's largest magnitude {scale:.6g})")
    return None


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
    here = machine()
    if args.record:
        if args.names or without:
            raise SystemExit("--record writes every run (the stored files and MACHINE belong together); "
                             "give no names and no --without")
        recorded_on = here
    elif os.path.exists(MACHINE_FILE):
        with open(MACHINE_FILE) as f:
            recorded_on = f.read().strip()
    else:
        recorded_on = None
    same_machine = recorded_on == here
    if not args.record:
        print("recorded on this machine: byte for byte" if same_machine else
              f"recorded on another machine ({recorded_on}; this one: {here}): every column within "
              f"{OTHER_MACHINE_TOLERANCE:g} of its largest magnitude")
    workdir = tempfile.mkdtemp(prefix="tribo-unchanged-")
    differ = 0
    try:
        if args.record:
            os.makedirs(STORED, exist_ok=True)
            with open(MACHINE_FILE, "w") as f:
                f.write(here + "\n")
        for name in args.names or [n for n in RUNS if MODULE.get(n) not in without]:
            now = run(name, args.tribo, workdir)
            path = os.path.join(STORED, name + ".csv")
            if args.record:
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
            elif same_machine:
                print(f"{name}: DIFFERS, {first_difference(stored, now)}")
                differ += 1
            elif (where := differs_beyond(stored, now, OTHER_MACHINE_TOLERANCE)) is not None:
                print(f"{name}: DIFFERS, {where}")
                differ += 1
            else:
                print(f"{name}: equal within {OTHER_MACHINE_TOLERANCE:g} ({len(now.splitlines()) - 1} rows; "
                      f"not byte for byte: {first_difference(stored, now)})")
    finally:
        shutil.rmtree(workdir)
    if differ:
        print(f"{differ} run(s) differ from tests/unchanged/", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
