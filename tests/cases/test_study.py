#!/usr/bin/python3
"""`tribo study`: two cases over two MPI ranks give the same summary rows as one after
another; with four ranks each case runs on two (unless a case cannot be split); an interrupted study resumes without redoing finished cases; changed fixed
parameters never mix with old results; bad study input fails before anything runs.
`tribo tradeoff` (Design = tradeoff): the reference and each ladder's rungs are run,
and tradeoff.csv holds the cost and the errors against the reference, recomputed here
from each case's own outputs.

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

import numpy as np

TRIBO = None

BASE = """
subsection Simulation
  set Scene = shear
  set Time step = 2e-9
  set End time = 2e-6
end
subsection Solver
  set Residual target = 3e-3
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

TRADEOFF = """
subsection Study
  set Base case = base.prm
  set Design = tradeoff
  set Parameters = Solver/Residual target = 1e-2, 1e-3; Simulation/Time step = 4e-9
  set Reference = {reference}
end
"""

PHYSICS = ["case", "Contact law/Cohesion", "status", "mu_mean", "mu_std", "power_balance_ratio",
           "normal_force_mean", "sigma_yy_mean", "sigma_xy_mean", "cohesion_number"]


def table(directory):
    with open(os.path.join(directory, "study_summary.csv")) as f:
        return [{k: r[k] for k in PHYSICS} for r in csv.DictReader(f)]


class WithBaseCase(unittest.TestCase):
    """A temporary directory holding base.prm (BASE)."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        with open(os.path.join(self.dir, "base.prm"), "w") as f:
            f.write(BASE)

    def tearDown(self):
        self.tmp.cleanup()


class Study(WithBaseCase):
    def setUp(self):
        super().setUp()
        self.write_study()

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

    def test_more_ranks_than_cases_give_each_case_several(self):
        self.study("serial")
        log = self.study("four", mpi_ranks=4)
        self.assertIn("study: 4 MPI ranks for 2 cases: each case on 2 ranks", log)
        self.assertIn("case 1 (rank 1 and 1 more): running", log)
        for case in ("case_000", "case_001"):
            with open(os.path.join(self.dir, "four", case, "log.txt")) as f:
                self.assertEqual(f.read().count("the contacts of each step split over 2 MPI ranks"), 1)
        # 50 discs: under 64 contacts per rank a step is solved whole on every rank, the serial bits.
        self.assertEqual(table(os.path.join(self.dir, "serial")), table(os.path.join(self.dir, "four")))
        # A study whose cases cannot be split runs one case per rank.
        self.write_study("; Solver/Method = interior-point")
        log = self.study("ip", mpi_ranks=4)
        self.assertNotIn("each case on", log)
        self.assertIn("case 1 (rank 1): running", log)

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
        # The message names the study file and the case the bad value makes.
        self.assertIn("study.prm: case 1 (", p.stderr)
        self.assertIn("Contact law/Cohesion=-5", p.stderr)
        self.assertFalse(os.path.exists(out))


SHARED = """
subsection Study
  set Base case = base.prm
  set Parameters = Shear cell/Sliding velocity = 2, 5; Contact law/Cohesion = 0, 120
  set Fixed = Contact law/Cohesion range = 2.4e-8
  set Shear-phase entries = {shear_phase}
end
"""


class SharedCompaction(WithBaseCase):
    """Cases that differ only in what acts after Shear start (and the study's Shear-phase
    entries) shear from one compaction, run once, and give exactly what each gives run
    alone from that state (Shear cell/Initial state)."""

    def study(self, shear_phase):
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(SHARED.format(shear_phase=shear_phase))
        out = os.path.join(self.dir, "out")
        p = subprocess.run([TRIBO, "study", os.path.join(self.dir, "study.prm"), "--output", out],
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        return p.stdout, out

    def test_one_compaction_and_each_case_equals_its_run_from_the_state(self):
        log, out = self.study("Contact law/Cohesion")
        note = "4 cases shear from 1 shared compaction"
        self.assertIn(note, log)
        with open(os.path.join(out, "study_summary.md")) as f:
            self.assertIn("Compaction: " + note, f.read())
        self.assertEqual(sorted(d for d in os.listdir(out) if d.startswith("preparation")), ["preparation_000"])
        prep = os.path.join(out, "preparation_000")
        with open(os.path.join(prep, "summary.json")) as f:
            p = json.load(f)
        # The compaction runs to Shear start (6e-7 s: 300 steps of 2e-9 s) with the base
        # case's cohesion (0).
        self.assertEqual((p["status"], p["steps"]), ("complete", 300))
        self.assertAlmostEqual(p["simulated_time"], 6e-7, delta=1e-15)
        with open(os.path.join(prep, "parameters.prm")) as f:
            self.assertRegex(f.read(), r"set Cohesion\s+= 0\s")
        with open(os.path.join(out, "study_summary.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([r["preparation"] for r in rows], ["preparation_000"] * 4)
        self.assertEqual([r["status"] for r in rows], ["complete"] * 4)
        self.assertEqual(len({r["mu_mean"] for r in rows}), 4)  # four different shear phases
        for r in rows:
            # "mu_stderr" is the batch-means standard error: positive, below the spread.
            self.assertGreater(float(r["mu_stderr"]), 0)
            self.assertLess(float(r["mu_stderr"]), float(r["mu_std"]))

        # Case 3 (V = 5 m/s, cohesion 120 N/m) run alone from the same state: the same rows.
        alone = os.path.join(self.dir, "alone")
        run = subprocess.run([TRIBO, "run", os.path.join(self.dir, "base.prm"), "--output", alone, "--quiet",
                              "--set", "Shear cell/Sliding velocity=5", "--set", "Contact law/Cohesion=120",
                              "--set", "Contact law/Cohesion range=2.4e-8",
                              "--set", "Shear cell/Initial state=" + prep], capture_output=True, text=True,
                             timeout=120)
        self.assertEqual(run.returncode, 0, run.stderr)
        with open(os.path.join(alone, "statistics.csv")) as f:
            alone_rows = f.read()
        with open(os.path.join(out, "case_003", "statistics.csv")) as f:
            self.assertEqual(f.read(), alone_rows)
        with open(os.path.join(alone, "summary.json")) as f:
            s = json.load(f)
        # It runs the 700 steps from 6e-7 s to 2e-6 s only, starting from the state's time.
        self.assertEqual((s["steps"], s["start_time"]), (700, p["simulated_time"]))
        self.assertAlmostEqual(float(alone_rows.splitlines()[1].split(",")[0]), 6e-7 + 10 * 2e-9, delta=1e-15)
        self.assertIn("starting from the state of " + prep, open(os.path.join(alone, "log.txt")).read())

        # A second run of the study redoes nothing.
        log, _ = self.study("Contact law/Cohesion")
        self.assertIn("preparation 0: complete, skipped", log)
        self.assertNotIn("running", log)

    def test_a_deformable_body_takes_the_walls_place_on_the_shared_compaction(self):
        check = subprocess.run([TRIBO, "check", os.path.join(self.dir, "base.prm"), "--set",
                                "Shear cell/Upper body model=fem"], capture_output=True, text=True, timeout=60)
        if "left out" in check.stderr:
            self.skipTest("built without TRIBO_WITH_FEM")
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(SHARED.format(shear_phase="Shear cell/Upper body model").replace(
                "Shear cell/Sliding velocity = 2, 5; Contact law/Cohesion = 0, 120",
                "Shear cell/Upper body model = rigid, fem"))
        out = os.path.join(self.dir, "bodies")
        p = subprocess.run([TRIBO, "study", os.path.join(self.dir, "study.prm"), "--output", out],
                           capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("2 cases shear from 1 shared compaction", p.stdout)
        prep = np.genfromtxt(os.path.join(out, "preparation_000", "statistics.csv"), delimiter=",", names=True)
        fem = np.genfromtxt(os.path.join(out, "case_001", "statistics.csv"), delimiter=",", names=True)
        with open(os.path.join(out, "case_001", "summary.json")) as f:
            self.assertEqual(json.load(f)["status"], "complete")
        # The body's surface stands where the wall's was: 10 steps on, the layer's solid
        # fraction is the compacted one.
        self.assertAlmostEqual(fem["solid_fraction"][0] / prep["solid_fraction"][-1], 1, delta=1e-6)
        # It takes its load from the state's time on: 10 steps into the 100-step ramp.
        self.assertAlmostEqual(fem["normal_force"][0] / (1e8 * 1.2e-5), 0.1, delta=1e-9)
        self.assertAlmostEqual(fem["normal_force"][-1] / (1e8 * 1.2e-5), 1, delta=1e-9)
        # Run alone from the same state (its own process, deal.II's threads as in the study's
        # serial process): the same rows.
        alone = os.path.join(self.dir, "fem_alone")
        run = subprocess.run([TRIBO, "run", os.path.join(self.dir, "base.prm"), "--output", alone, "--quiet",
                              "--set", "Shear cell/Upper body model=fem", "--set",
                              "Shear cell/Initial state=" + os.path.join(out, "preparation_000")],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(run.returncode, 0, run.stderr)
        with open(os.path.join(alone, "statistics.csv")) as a, \
                open(os.path.join(out, "case_001", "statistics.csv")) as b:
            self.assertEqual(a.read(), b.read())

    def test_the_compaction_follows_the_entries_that_act_before_shear_start(self):
        # Without Shear-phase entries the cohesion acts in the compaction too: one
        # compaction per cohesion, each shared by the two sliding velocities.
        log, out = self.study("")
        self.assertIn("4 cases shear from 2 shared compactions", log)
        with open(os.path.join(out, "study_summary.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([r["preparation"] for r in rows],
                         ["preparation_000", "preparation_001", "preparation_000", "preparation_001"])
        with open(os.path.join(out, "preparation_001", "parameters.prm")) as f:
            self.assertRegex(f.read(), r"set Cohesion\s+= 120\s")
        # Cases that differ in the compaction itself share nothing.
        with open(os.path.join(self.dir, "study.prm"), "w") as f:
            f.write(SHARED.format(shear_phase="").replace("Shear cell/Sliding velocity = 2, 5; ", ""))
        p = subprocess.run([TRIBO, "study", os.path.join(self.dir, "study.prm"), "--output",
                            os.path.join(self.dir, "apart")], capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("no shared compaction: every case compacts differently", p.stdout)
        self.assertFalse([d for d in os.listdir(os.path.join(self.dir, "apart")) if d.startswith("preparation")])


class Tradeoff(WithBaseCase):
    def tradeoff(self, reference, command="tradeoff", design="tradeoff"):
        path = os.path.join(self.dir, "tradeoff.prm")
        with open(path, "w") as f:
            f.write(TRADEOFF.format(reference=reference).replace("Design = tradeoff", "Design = " + design))
        out = os.path.join(self.dir, "out")
        p = subprocess.run([TRIBO, command, path, "--output", out, "--quiet"], capture_output=True, text=True,
                           timeout=600)
        return p, path, out

    def test_cost_and_errors_against_the_reference(self):
        # The default method's own accuracy knob, Residual target, against 1e-4.
        p, _, out = self.tradeoff("Solver/Residual target = 1e-4; Simulation/Time step = 2e-9")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        with open(os.path.join(out, "tradeoff.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([(r["knob"], r["value"]) for r in rows],
                         [("reference", "Solver/Residual target = 1e-4; Simulation/Time step = 2e-9"),
                          ("Solver/Residual target", "1e-2"), ("Solver/Residual target", "1e-3"),
                          ("Simulation/Time step", "4e-9")])
        self.assertEqual([r["status"] for r in rows], ["complete"] * 4)

        def outputs(r):
            d = os.path.join(out, r["directory"])
            with open(os.path.join(d, "summary.json")) as f:
                s = json.load(f)
            return s, np.genfromtxt(os.path.join(d, "profiles.csv"), delimiter=",", names=True)

        ref_summary, ref_profiles = outputs(rows[0])
        mu_ref = ref_summary["results"]["mu_mean"]
        self.assertEqual(float(rows[0]["cost_ratio"]), 1.0)
        for q in ("mu_error", "vx_l2", "sigma_yy_l2", "sigma_xy_l2"):
            self.assertEqual(float(rows[0][q]), 0.0, q)
        for r in rows:
            s, prof = outputs(r)
            self.assertAlmostEqual(float(r["cost"]), s["wall_time"] / (s["simulated_time"] * 1e6),
                                   delta=1e-9 * float(r["cost"]))
            self.assertAlmostEqual(float(r["mu_error"]), abs(s["results"]["mu_mean"] - mu_ref) / abs(mu_ref),
                                   delta=1e-12)
            self.assertAlmostEqual(float(r["balance_residual"]), abs(1 - s["results"]["power_balance_ratio"]),
                                   delta=1e-12)
            syy = np.interp(ref_profiles["y_over_h"], prof["y_over_h"], prof["sigma_yy"])
            self.assertAlmostEqual(float(r["sigma_yy_l2"]),
                                   np.linalg.norm(syy - ref_profiles["sigma_yy"]) /
                                   np.linalg.norm(ref_profiles["sigma_yy"]), delta=1e-12)
        # A looser target buys its speed with fewer iterations (APGS's sweeps and checks).
        self.assertLess(float(rows[1]["solver_iterations_per_step"]), float(rows[0]["solver_iterations_per_step"]))
        # The time-step rung really ran at its step (half the steps of the reference).
        self.assertEqual(outputs(rows[3])[0]["steps"] * 2, ref_summary["steps"])
        with open(os.path.join(out, "tradeoff.md")) as f:
            self.assertIn("its standard error (batch means)", f.read())
        self.assertGreater(os.path.getsize(os.path.join(out, "tradeoff.png")), 10000)

    def test_collision_ladder_converges_at_first_order(self):
        # The shipped collision ladder (cases/collision/tradeoff.prm): the ELAS collision
        # at 2 m/s loses energy only through the step, at first order: loss ~ C dt/dt*.
        case = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "cases", "collision",
                            "tradeoff.prm")
        out = os.path.join(self.dir, "collision")
        p = subprocess.run([TRIBO, "tradeoff", case, "--output", out, "--quiet"], capture_output=True,
                           text=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        with open(os.path.join(out, "tradeoff.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([r["status"] for r in rows], ["complete"] * len(rows))
        self.assertTrue(all(r["outcome_as_reference"] == "True" for r in rows))
        with open(os.path.join(out, rows[0]["directory"], "summary.json")) as f:
            ref = json.load(f)["results"]
        ladder = [r for r in rows if r["knob"] == "Collision/Time step ratio" and r["value"] != "10000"]
        ratios = [float(r["value"]) for r in ladder]
        self.assertEqual(ratios, [3, 10, 30, 100, 300, 1000])
        errors = [float(r["restitution_error"]) for r in ladder]
        self.assertEqual(errors, sorted(errors, reverse=True))  # finer steps, smaller errors
        for r, ratio in zip(ladder, ratios):
            self.assertAlmostEqual(float(r["restitution_error"]),
                                   abs(float(r["restitution"]) - ref["restitution_coefficient"]), delta=1e-12)
            if ratio >= 10:
                self.assertGreater(float(r["energy_loss"]) * ratio, 1.4)
                self.assertLess(float(r["energy_loss"]) * ratio, 2.0)
        # One contact: every tolerance converges in the first sweep, the same result.
        tolerance = [r for r in rows if r["knob"] == "Solver/Tolerance"]
        self.assertEqual(len({r["restitution"] for r in tolerance}), 1)

    def test_bad_tradeoff_input_fails_before_running(self):
        p, path, out = self.tradeoff("Contact law/Cohesion = 60")
        self.assertEqual(p.returncode, 2)
        self.assertEqual(p.stderr.strip(), "error: %s:6: 'Contact law/Cohesion' is not one of the "
                         "Parameters (the ladders)" % path)
        self.assertFalse(os.path.exists(out))
        p, path, out = self.tradeoff("Solver/Residual target = 1e-4", design="combinations")
        self.assertEqual(p.returncode, 2)
        self.assertEqual(p.stderr.strip(), "error: %s:4: entry 'Study/Design' = 'combinations': expected "
                         "'tradeoff' for `tribo tradeoff` (or run the file with `tribo study`)" % path)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: test_study.py PATH/TO/tribo")
    TRIBO = os.path.abspath(sys.argv.pop(1))
    unittest.main(verbosity=2)
