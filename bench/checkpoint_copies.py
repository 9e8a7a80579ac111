"""Runs that go on from a copy of one checkpoint, as bench/solver_methods.sh and
bench/step_uniqueness.sh make them: each setting resumes a fresh copy of the run directory
with its own --set entries, on one core and without fields, plots or new checkpoints."""
import os
import re
import shutil
import subprocess
import sys

#: Entries every resumed copy gets first (a setting's own entries come later and win).
FIXED = ["Solver/Threads=1", "Solver/Streams=1", "Output/Field interval=0", "Output/Plots=false",
         "Output/Statistics interval=1", "Output/Checkpoint interval=0", "Output/Checkpoint step interval=0"]


def entries(setting):
    """A SETTING string, space-separated Section/Entry=value items, as a list of --set values."""
    return [s.strip() for s in re.split(r"\s+(?=[A-Z][A-Za-z ]*/)", setting.strip()) if s.strip()]


def resume(tribo, src, dst, end, extra):
    """Copy the run @p src to @p dst and resume it there up to Simulation/End time @p end with
    the --set entries @p extra; the step it resumed at. Exits naming @p src when the
    checkpoint did not resume; a run that fails later is left for the caller to read."""
    shutil.rmtree(dst, ignore_errors=True)
    shutil.copytree(src, dst)
    args = [tribo, "run", os.path.join(dst, "parameters.prm"), "--resume", dst, "--quiet"]
    for s in FIXED + ["Simulation/End time=%.17g" % end] + extra:
        args += ["--set", s]
    with open(os.path.join(dst, "log.txt")) as f:
        before = f.read().count("resumed at step")
    run = subprocess.run(args, capture_output=True, text=True)
    with open(os.path.join(dst, "log.txt")) as f:
        resumed = re.findall(r"resumed at step (\d+)", f.read())
    if len(resumed) == before:
        sys.exit(f"{src}: the checkpoint did not resume: {run.stderr.strip()[:300]}")
    return int(resumed[-1])
