"""Checkpoints and `tribo run CASE.prm --resume DIR`:

- a shear run killed with SIGKILL after a checkpoint and resumed gives the same
  statistics.csv, profiles.csv, results.h5 statistics and summary results as the run
  done in one go, bit for bit (the checkpoint holds every double exactly);
- the same with the deal.II upper body, stopped by SIGTERM (which writes a checkpoint
  of the last step done) instead of SIGKILL;
- a resumed run may change Solver/*, Output/* and End time (logged), nothing else:
  exact error messages for another entry, for a damaged checkpoint, for a directory
  without a checkpoint and for a complete run (whose checkpoint is removed).

Usage: /usr/bin/python3 test_resume.py /path/to/tribo
"""

import filecmp
import os
import shutil
import signal
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import TempDirTestCase, read_json, read_pvd, run, run_and_stop, write_prm  # noqa: E402

#: 3000 steps of a 60-disc shear cell, sliding from step 100, a checkpoint every 500 steps.
CASE = {
    "Simulation": {"Scene": "shear", "Time step": "2e-9", "End time": "6e-6"},
    "Solver": {"Tolerance": "1e-3"},
    "Shear cell": {"Number of discs": "60", "Length": "1.2e-5", "Wall discs": "0",
                   "Pressure ramp time": "1e-7", "Shear start": "2e-7", "Profile samples": "50"},
    "Output": {"Statistics interval": "1", "Field interval": "1000", "Plots": "false",
               "Checkpoint step interval": "500"},
}


class Resume(TempDirTestCase):
    def write_case(self, changes=None):
        sections = {k: dict(v) for k, v in CASE.items()}
        for path, value in (changes or {}).items():
            section, entry = path.split("/")
            sections.setdefault(section, {})[entry] = value
        write_prm(os.path.join(self.tmp, "case.prm"), sections)

    def run_ok(self, args):
        r = run(args, self.tmp, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r

    def run_and_stop(self, out, sig, after_checkpoint_s=0.3):
        """Start a run into @p out, send @p sig once its first checkpoint exists."""
        run_and_stop(self, self.tmp, "case.prm", out, sig, after_checkpoint_s)

    def assert_same_run(self, ref, resumed):
        a, b = os.path.join(self.tmp, ref), os.path.join(self.tmp, resumed)
        for name in ("statistics.csv", "profiles.csv"):
            self.assertTrue(filecmp.cmp(os.path.join(a, name), os.path.join(b, name), shallow=False),
                            "%s differs between the run in one go and the resumed one" % name)
        sa, sb = read_json(os.path.join(a, "summary.json")), read_json(os.path.join(b, "summary.json"))
        self.assertEqual(sb["status"], "complete")
        self.assertEqual(sa["results"], sb["results"])
        for key in ("steps", "solver_iterations_total", "solver_iterations_max", "max_overlap",
                    "n_field_snapshots"):
            self.assertEqual(sa[key], sb[key], key)
        with h5py.File(os.path.join(a, "results.h5"), "r") as fa, \
                h5py.File(os.path.join(b, "results.h5"), "r") as fb:
            for name in fa["statistics"]:
                np.testing.assert_array_equal(fa["statistics"][name][()], fb["statistics"][name][()],
                                              err_msg=name)
        self.assertEqual(read_pvd(os.path.join(a, "fields", "discs.pvd")),
                         read_pvd(os.path.join(b, "fields", "discs.pvd")))
        self.assertFalse(os.path.exists(os.path.join(b, "checkpoint.bin")),
                         "a complete run removes its checkpoint")
        with open(os.path.join(b, "log.txt")) as f:
            log = f.read()
        self.assertIn("resumed at step ", log)
        return sb

    def test_sigkill_then_resume_is_bit_identical(self):
        self.write_case()
        self.run_ok(["run", "case.prm", "--output", "ref", "--quiet"])
        self.run_and_stop("out", signal.SIGKILL)
        self.run_ok(["run", "case.prm", "--resume", "out", "--quiet"])
        s = self.assert_same_run("ref", "out")
        self.assertGreater(s["results"]["profile_samples_in_steady_state"], 0)

    def test_fem_upper_body_sigterm_then_resume_is_bit_identical(self):
        self.write_case({"Shear cell/Upper body model": "fem", "Simulation/End time": "3e-6"})
        self.run_ok(["run", "case.prm", "--output", "ref", "--quiet"])
        self.run_and_stop("out", signal.SIGTERM)
        self.assertEqual(read_json(os.path.join(self.tmp, "out", "summary.json"))["status"], "interrupted")
        self.run_ok(["run", "case.prm", "--resume", "out", "--quiet"])
        self.assert_same_run("ref", "out")
        self.assertEqual(read_pvd(os.path.join(self.tmp, "ref", "fields", "upper_body.pvd")),
                         read_pvd(os.path.join(self.tmp, "out", "fields", "upper_body.pvd")))

    def test_what_a_resumed_run_may_change(self):
        self.write_case({"Simulation/End time": "2e-6"})
        self.run_and_stop("out", signal.SIGTERM, after_checkpoint_s=0)
        r = run(["run", "case.prm", "--resume", "out", "--quiet", "--set", "Shear cell/Sliding velocity=4"],
                self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip(),
                         "error: --resume out: entry 'Shear cell/Sliding velocity' is '4' in the case but "
                         "'5' in the checkpoint; a resumed run may change only Solver/*, Output/*, "
                         "Simulation/End time, Simulation/Most substeps, Simulation/Most substeps on retake and "
                         "Shear cell/Upper body prediction depth")
        self.assertEqual(read_json(os.path.join(self.tmp, "out", "summary.json"))["status"], "interrupted",
                         "a refused resumption leaves the run as it was")
        # A checkpoint whose first count after the header is 2^60 (another build's layout,
        # or a damaged file): a clear error, not the allocator's.
        shutil.copytree(os.path.join(self.tmp, "out"), os.path.join(self.tmp, "damaged"))
        path = os.path.join(self.tmp, "damaged", "checkpoint.bin")
        with open(path, "rb") as f:
            data = f.read()
        at = data.index(b"tribo checkpoint ") + len(b"tribo checkpoint 4")
        with open(path, "wb") as f:
            f.write(data[:at] + (1 << 60).to_bytes(8, "little") + data[at + 8:])
        r = run(["run", "case.prm", "--resume", "damaged", "--quiet"], self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertRegex(r.stderr.strip(), r"^error: checkpoint \S*damaged/checkpoint.bin: unreadable \(.+\); it "
                                           r"was written by another build or for another case$")
        self.run_ok(["run", "case.prm", "--resume", "out", "--quiet", "--set", "Solver/Tolerance=5e-4",
                     "--set", "Simulation/End time=2.2e-6"])
        s = read_json(os.path.join(self.tmp, "out", "summary.json"))
        self.assertEqual((s["status"], s["steps"]), ("complete", 1100))
        with open(os.path.join(self.tmp, "out", "log.txt")) as f:
            self.assertIn("; changed: Simulation/End time 2e-6 -> 2.2e-6, Solver/Tolerance 1e-3 -> 5e-4",
                          f.read())

        r = run(["run", "case.prm", "--resume", "out", "--quiet"], self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip(),
                         "error: --resume out: no checkpoint.bin there (the run is complete: nothing to resume)")
        os.makedirs(os.path.join(self.tmp, "empty"))
        r = run(["run", "case.prm", "--resume", "empty", "--quiet"], self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("error: --resume empty: no checkpoint.bin there (none was written", r.stderr)


if __name__ == "__main__":
    tribo_cli.main()
