#!/usr/bin/python3
"""`tribo study`: two cases over two MPI ranks give the same summary rows as one after
another; an interrupted study resumes without redoing finished cases; changed fixed
parameters never mix with old results; bad study input fails before anything runs.

Usage: test_study.py PATH/TO/tribo
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

TRIBO = None

BASE = """
subsection Simulation
  set Scene = shear
  set Time step = 2e-9
  set End time = 2e-6
end
subsection Solver
  set Tolerance = 1e-3
end
subsection Shear cell
  set Number of discs = 50
  set Length = 1.2e-5
  set Wall discs = 0
  set Pressure ramp time = 2e-7
  set Shear start = 6e-7
  set Profile samples = 20
end
subsection Output
  set Statistics interval = 10
  set Plots = false
end
"""

STUDY = """
subsection Study
  set Base case = base.prm
  set Parameters = Contact law/Cohesion = 0, 120
  set Fixed = Contact law/Cohesion range = 2.4e-8{extra}
end
"""

PHYSICS = ["case", "Contact law/Cohesion", "status", "mu_mean", "mu_std", "power_balance_ratio",
           "normal_force_mean", "sigma_yy_mean", "sigma_xy_mean", "cohesion_number"]


def table(directory):
    with open(os.path.join(directory, "study_summary.csv")) as f:
        return [{k: r[k] for k in PHYSICS} for r in csv.DictReader(f)]


class Study(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        with open(os.path.join(self.dir, "base.prm"), "w") as f:
            f.write(BASE)
        self.write_study()

    def tearDown(self):
        self.tmp.cleanup()

    def write_study(self, extra=""):
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(STUDY.format(extra=extra))

    def study(self, out, mpi_ranks=0):
        cmd = [TRIBO, "study", os.path.join(self.dir, "study.prm"), "--output", os.path.join(self.dir, out)]
        env = dict(os.environ)
        if mpi_ranks:
            mpirun = shutil.which("mpirun")
            self.assertIsNotNone(mpirun, "mpirun (openmpi-bin) is installed by scripts/install-deps")
            cmd = [mpirun, "-np", str(mpi_ranks), "--oversubscribe"] + cmd
            env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       OMPI_MCA_rmaps_base_oversubscribe="1")
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        return p.stdout

    def test_two_ranks_give_the_rows_of_one_after_another(self):
        self.study("serial")
        self.study("parallel", mpi_ranks=2)
        serial, parallel = table(os.path.join(self.dir, "serial")), table(os.path.join(self.dir, "parallel"))
        self.assertEqual(len(serial), 2)
        self.assertEqual([r["status"] for r in serial], ["complete", "complete"])
        self.assertEqual(serial, parallel)  # bit-identical physics, whatever the rank
        self.assertNotEqual(serial[0]["mu_mean"], serial[1]["mu_mean"])  # two different cases

    def test_interrupted_study_resumes_without_redoing_finished_cases(self):
        out = os.path.join(self.dir, "s")
        self.study("s")
        before = table(out)
        done = os.path.join(out, "case_000", "summary.json")
        stamp = os.stat(done).st_mtime_ns
        # Case 1 as a crash leaves it: summary.json still says "running".
        with open(os.path.join(out, "case_001", "summary.json"), "w") as f:
            json.dump({"status": "running"}, f)
        log = self.study("s")
        self.assertIn("case 0: complete, skipped", log)
        self.assertIn("case 1 (rank 0): running", log)
        self.assertEqual(os.stat(done).st_mtime_ns, stamp, "a finished case was run again")
        self.assertEqual(table(out), before)

    def test_changed_fixed_parameters_rerun_every_case(self):
        out = os.path.join(self.dir, "s")
        self.study("s")
        before = table(out)
        self.write_study("; Shear cell/Sliding velocity = 2")
        log = self.study("s")
        self.assertNotIn("skipped", log)
        after = table(out)
        self.assertNotEqual([r["mu_mean"] for r in after], [r["mu_mean"] for r in before])
        with open(os.path.join(out, "case_000", "study.prm")) as f:
            self.assertIn("Shear cell/Sliding velocity=2", f.read())

    def test_a_failed_case_is_a_row_and_the_others_go_on(self):
        # A detection distance of 1e-4 m makes the contact reach longer than half the
        # period: the run stops with an error at its first step (RunError, exit 1).
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(STUDY.format(extra="").replace("Contact law/Cohesion = 0, 120",
                                                   "Contact law/Detection distance = 1e-4, 0"))
        out = os.path.join(self.dir, "f")
        self.study("f")
        with open(os.path.join(out, "study_summary.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([r["status"] for r in rows], ["failed", "complete"])
        self.assertIn("period along x", rows[0]["error"])
        self.assertNotEqual(rows[1]["mu_mean"], "")

    def test_bad_study_input_fails_before_running(self):
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(STUDY.format(extra="").replace("Cohesion = 0, 120", "Cohesion = 0, -5"))
        out = os.path.join(self.dir, "bad")
        p = subprocess.run([TRIBO, "study", os.path.join(self.dir, "study.prm"), "--output", out],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 2)
        self.assertIn("entry 'Contact law/Cohesion' = '-5': expected a cohesion >= 0 in N/m", p.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: test_study.py PATH/TO/tribo")
    TRIBO = os.path.abspath(sys.argv.pop(1))
    unittest.main(verbosity=2)
