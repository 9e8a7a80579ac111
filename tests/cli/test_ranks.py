"""One case on several MPI ranks, `mpirun -np N tribo run` (docs/scaling.md):

- on two ranks the 120-disc shear cell gives the serial run's friction, stress, solid fraction
  and power balance within their combined standard errors, every step within the solver's
  law residual target, and one set of outputs (rank 0 writes, the others say nothing); each
  rank writes its band of the discs and loaded contacts as a piece of each field snapshot,
  indexed by .pvtu records: the first snapshot holds the serial run's discs exactly, the last
  every disc and every loaded contact once;
- a checkpoint written on two ranks (stopped by SIGTERM) resumes on one rank (to the end)
  and on three (300 steps): the rows before the checkpoint are kept bit for bit and both
  complete within the residual target;
- NLGS on two ranks stops by its own norm (Quad 1e-4 over both ranks' contacts) at about the
  serial sweeps;
- with the deal.II first body (its half-disc contacts on the top band's rank, its update
  repeated on every rank) two ranks complete every step, so the body's node velocities were
  the same bits on both ranks at every solve (a step stops otherwise), and give the serial
  run's friction, stress, solid fraction and power balance within their combined standard
  errors at a law residual of 1e-5; with the sph and mlp bodies two ranks complete 600 steps
  past the body's landing, every step converged and the body loaded;
- what is not split over ranks is refused with the cause and the remedy, before anything is
  written: another solver method, NLGS in another order.

Usage: /usr/bin/python3 test_ranks.py /path/to/tribo
"""

import csv
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import TempDirTestCase, pvtu_pieces, read_json, read_pvd, read_vtu_with_vtk, run, write_prm  # noqa: E402

#: cases/shear/small.prm without plots: 120 discs, 8000 steps, APGS to a law residual of 3e-3.
TARGET = 3e-3
CASE = {
    "Simulation": {"Scene": "shear", "Time step": "2e-9", "End time": "1.6e-5"},
    "Contact law": {"Law": "IQS", "Cohesion range": "2.4e-8"},
    "Solver": {"Residual target": str(TARGET)},
    "Shear cell": {"Number of discs": "120", "Length": "1.2e-5", "Wall discs": "0", "Pressure": "1e8",
                   "Pressure ramp time": "1e-6", "Sliding velocity": "5", "Shear start": "3e-6",
                   "Profile samples": "3000"},
    "Output": {"Field interval": "0", "Plots": "false"},
}
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def mpirun(ranks, args):
    """`tribo ARGS` on @p ranks MPI ranks (oversubscribed: two cores test correctness here)."""
    launcher = shutil.which("mpirun")
    assert launcher, "mpirun (openmpi-bin) is installed by scripts/install-deps"
    return [launcher, "-np", str(ranks), "--oversubscribe", tribo_cli.TRIBO] + list(args)


def statistics(path):
    with open(os.path.join(path, "statistics.csv")) as f:
        return list(csv.reader(f))


class Ranks(TempDirTestCase):
    def setUp(self):
        super().setUp()
        write_prm(os.path.join(self.tmp, "case.prm"), CASE)

    def run_ranks(self, ranks, args, timeout=300):
        return subprocess.run(mpirun(ranks, args), cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True, timeout=timeout, env=MPI_ENV)

    def assert_within_errors(self, a, b, name, errors=3):
        """Two runs' means within @p errors combined standard errors: two trajectories apart
        from the first steps' round-off, so a realisation falls outside 2 errors one time in
        twenty for each quantity (four quantities: more than one run in ten), outside 3 one
        time in 370."""
        ra, rb = a["results"], b["results"]
        mean = name + "_mean" if name + "_mean" in ra else name
        combined = math.hypot(ra[name + "_stderr"], rb[name + "_stderr"])
        self.assertLess(abs(ra[mean] - rb[mean]), errors * combined,
                        "%s: %g +/- %g against %g +/- %g" % (name, ra[mean], ra[name + "_stderr"],
                                                             rb[mean], rb[name + "_stderr"]))

    def assert_solved_to_target(self, out, whole_run=True):
        s = read_json(os.path.join(self.tmp, out, "summary.json"))
        self.assertEqual(s["status"], "complete")
        self.assertEqual(s["solver_non_converged_steps"], 0)
        self.assertLessEqual(s["law_residual_max"], TARGET * (1 + 1e-9))
        if whole_run:  # the power balance over its steady state: the books close to round-off
            self.assertAlmostEqual(s["results"]["power_balance_closure"], 1, delta=1e-9)
        return s

    def test_two_ranks_give_the_serial_friction_and_one_set_of_outputs(self):
        # 20 000 steps: over the case's 8000 a realisation's mu moves by 0.02 (0.1087 +/- 0.0035
        # against 0.1277 +/- 0.0050 serial), over 20 000 by 0.004.
        longer = ["--set", "Simulation/End time=4e-5"]
        r = run(["run", "case.prm", "--output", "one", "--quiet"] + longer, self.tmp, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = self.run_ranks(2, ["run", "case.prm", "--output", "two"] + longer)
        self.assertEqual(r.returncode, 0, r.stderr)
        # One log: rank 0's, on the terminal and in log.txt.
        self.assertEqual(r.stdout.count("tribo run case.prm -> two"), 1, r.stdout)
        self.assertEqual(r.stdout.count("status complete"), 1, r.stdout)
        with open(os.path.join(self.tmp, "two", "log.txt")) as f:
            log = f.read()
        self.assertEqual(log.count("the contacts of each step split over 2 MPI ranks"), 1)
        self.assertEqual(sorted(os.listdir(os.path.join(self.tmp, "one"))),
                         sorted(os.listdir(os.path.join(self.tmp, "two"))))
        one, two = self.assert_solved_to_target("one"), self.assert_solved_to_target("two")
        self.assertEqual(two["steps"], 20000)
        for name in ("mu", "sigma_xy", "solid_fraction", "power_balance_ratio"):
            self.assert_within_errors(one, two, name)
        # The split's own cost is timed as a part of the solve's, and only where there is a split.
        self.assertEqual(one["timing"]["exchange_mean_s"], 0)
        self.assertGreater(two["timing"]["exchange_mean_s"], 0)
        self.assertLess(two["timing"]["exchange_mean_s"], two["timing"]["solver_mean_s"])
        self.assert_fields_in_pieces(one, two)

    def assert_fields_in_pieces(self, one, two):
        """Each rank writes a band of the discs and of the loaded contacts as its piece of a
        snapshot, indexed by a .pvtu record: at the start the serial run's discs exactly, at
        the end every disc once and every loaded contact once."""
        fields = {out: os.path.join(self.tmp, out, "fields") for out in ("one", "two")}
        snapshots = {out: {kind: read_pvd(os.path.join(fields[out], kind + ".pvd")) for kind in ("discs", "contacts")}
                     for out in fields}
        self.assertEqual([t for t, _ in snapshots["one"]["discs"]], [t for t, _ in snapshots["two"]["discs"]])
        self.assertEqual(two["n_field_snapshots"], len(snapshots["two"]["discs"]))
        for kind in ("discs", "contacts"):
            for t, name in snapshots["two"][kind]:
                record = os.path.join(fields["two"], name)
                self.assertTrue(name.endswith(".pvtu"), name)
                self.assertEqual([os.path.basename(p) for p in pvtu_pieces(record)],
                                 [name.replace(".pvtu", ".%d.vtu" % i) for i in range(2)])

        def discs(out, index):
            d = read_vtu_with_vtk(self, os.path.join(fields[out], snapshots[out]["discs"][index][1]))
            columns = [d["points"][:, 0], d["points"][:, 1], d["point_data"]["radius"][:, 0],
                       d["point_data"]["body"][:, 0]]
            return np.array(sorted(zip(*columns)))

        first_one, first_two = discs("one", 0), discs("two", 0)
        self.assertEqual(first_two.shape, (two["n_discs"], 4))
        np.testing.assert_array_equal(first_one, first_two)
        last = discs("two", -1)
        self.assertEqual(len(last), two["n_discs"])
        self.assertEqual(len(np.unique(last[:, :2], axis=0)), two["n_discs"])  # no disc twice
        # The pieces are bands: every disc of rank 0's piece below every disc of rank 1's.
        record = os.path.join(fields["two"], snapshots["two"]["discs"][-1][1])
        low, high = (read_vtu_with_vtk(self, piece)["points"][:, 1] for piece in pvtu_pieces(record))
        self.assertEqual(len(low) + len(high), two["n_discs"])
        self.assertLessEqual(low.max(), high.min())
        contacts = read_vtu_with_vtk(self, os.path.join(fields["two"], snapshots["two"]["contacts"][-1][1]))
        rows = statistics(os.path.join(self.tmp, "two"))
        self.assertEqual(contacts["n_cells"], int(float(rows[-1][rows[0].index("n_active_contacts")])))

    def test_the_deal_ii_first_body_on_two_ranks_gives_the_serial_friction(self):
        # At a law residual of 1e-5: at the case's 3e-3 the friction moves with the solve's
        # details (0.110 +/- 0.004 serial against 0.124 +/- 0.005 on two ranks; at 1e-5 the
        # serial run gives 0.121 +/- 0.007, docs/scaling.md).
        args = ["--quiet", "--set", "Shear cell/Upper body model=fem", "--set", "Shear cell/Upper body Poisson ratio=0.25",
                "--set", "Shear cell/Upper body cell size=1.5e-6", "--set", "Shear cell/Shear start=7e-6",
                "--set", "Simulation/End time=2e-5", "--set", "Solver/Residual target=1e-5"]
        r = run(["run", "case.prm", "--output", "one"] + args, self.tmp, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = self.run_ranks(2, ["run", "case.prm", "--output", "two"] + args, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "two", "log.txt")) as f:
            self.assertIn("a deformable first body's on the top band's rank", f.read())
        results = []
        for out in ("one", "two"):
            s = read_json(os.path.join(self.tmp, out, "summary.json"))
            self.assertEqual((s["status"], s["steps"], s["solver_non_converged_steps"]), ("complete", 10000, 0))
            self.assertLessEqual(s["law_residual_max"], 1e-5 * (1 + 1e-9))
            # The whole energy book, the body's elastic and kinetic energy in it (measured
            # within 1.6e-3 of 1).
            self.assertAlmostEqual(s["results"]["power_balance_closure"], 1, delta=5e-3)
            results.append(s)
        for name in ("mu", "sigma_xy", "solid_fraction", "power_balance_ratio"):
            self.assert_within_errors(results[0], results[1], name)

    def test_the_particle_first_bodies_run_on_two_ranks(self):
        # The bodies of tests/cases/test_shear_particle_body.py; the body lands on the layer at
        # about 6.5 us, so 7.6 us holds some 600 steps of its contacts.
        for model, spacing in (("sph", "1.5e-6"), ("mlp", "2e-6")):
            args = ["run", "case.prm", "--output", model, "--quiet", "--set", "Shear cell/Upper body model=" + model,
                    "--set", "Shear cell/Upper body Poisson ratio=0.25", "--set", "Shear cell/Upper body cell size=" + spacing,
                    "--set", "Shear cell/Shear start=7e-6", "--set", "Simulation/End time=7.6e-6"]
            r = self.run_ranks(2, args)
            self.assertEqual(r.returncode, 0, model + ": " + r.stderr)
            s = read_json(os.path.join(self.tmp, model, "summary.json"))
            self.assertEqual((s["status"], s["steps"], s["solver_non_converged_steps"]), ("complete", 3800, 0), model)
            self.assertLessEqual(s["law_residual_max"], TARGET * (1 + 1e-9), model)
            rows = statistics(os.path.join(self.tmp, model))
            column = rows[0].index("elastic_energy_upper_body")
            self.assertGreater(float(rows[-1][column]), 0, model + ": the body carries the layer")

    def test_a_checkpoint_on_two_ranks_resumes_on_one_and_on_three(self):
        args = ["run", "case.prm", "--output", "two", "--quiet", "--set", "Output/Checkpoint step interval=1000"]
        proc = subprocess.Popen(mpirun(2, args), cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                universal_newlines=True, env=MPI_ENV)
        checkpoint = os.path.join(self.tmp, "two", "checkpoint.bin")
        deadline = time.monotonic() + 300
        while not os.path.exists(checkpoint):
            self.assertIsNone(proc.poll(), "the run ended before its first checkpoint")
            self.assertLess(time.monotonic(), deadline, "no checkpoint within 300 s")
            time.sleep(0.01)
        time.sleep(0.3)
        self.assertIsNone(proc.poll(), "the run ended before it could be stopped")
        proc.send_signal(signal.SIGTERM)  # mpirun passes it on to both ranks
        proc.communicate(timeout=120)
        stopped = read_json(os.path.join(self.tmp, "two", "summary.json"))
        self.assertEqual(stopped["status"], "interrupted")
        kept = statistics(os.path.join(self.tmp, "two"))
        last_step = int(float(kept[-1][1]))
        self.assertGreater(last_step, 0)
        self.assertLess(last_step, 8000)
        self.assertTrue(os.path.exists(checkpoint), "the stop writes a checkpoint of its last step")

        shutil.copytree(os.path.join(self.tmp, "two"), os.path.join(self.tmp, "on_one"))
        shutil.copytree(os.path.join(self.tmp, "two"), os.path.join(self.tmp, "on_three"))
        r = run(["run", "case.prm", "--resume", "on_one", "--quiet"], self.tmp, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        # Three ranks on two cores: every sweep's exchange waits for a rank the cores are not
        # running, so 300 steps more (End time may change on resume).
        end = "Simulation/End time=%.17g" % ((last_step + 300) * 2e-9)
        r = self.run_ranks(3, ["run", "case.prm", "--resume", "on_three", "--quiet", "--set", end])
        self.assertEqual(r.returncode, 0, r.stderr)
        for out, steps in (("on_one", 8000), ("on_three", last_step + 300)):
            self.assert_solved_to_target(out, whole_run=out == "on_one")
            rows = statistics(os.path.join(self.tmp, out))
            self.assertEqual(rows[:len(kept)], kept, "%s rewrote the rows before the checkpoint" % out)
            self.assertEqual(int(float(rows[-1][1])), steps)
            self.assertFalse(os.path.exists(os.path.join(self.tmp, out, "checkpoint.bin")))

    def test_an_overlap_grown_over_steps_stops_one_and_two_ranks_naming_its_contact(self):
        # At 1e10 Pa (100 times the paper's) IQS keeps the overlaps that each step's solve leaves
        # within its tolerance: one grows to the smallest radius. The stop names the deepest
        # contact wherever its rank; its overlap at the step's start is the one the previous
        # step ended with (statistics.csv, every step), and the step added little to it.
        args = ["--quiet", "--set", "Shear cell/Pressure=1e10", "--set", "Simulation/End time=6e-6",
                "--set", "Output/Statistics interval=1"]
        pattern = (r"an overlap of (\S+) m, more than the smallest disc radius \((\S+) m\).*The deepest contact, "
                   r"between body (\d+) and body (\d+), overlapped by (\S+) m at the step's start and closed by "
                   r"(\S+) m in the step: the overlap does not come from the step size")
        for ranks in (1, 2):
            out = "r%d" % ranks
            r = self.run_ranks(ranks, ["run", "case.prm", "--output", out] + args)
            self.assertEqual(r.returncode, 1, r.stderr)
            found = re.search(pattern, r.stderr)
            self.assertIsNotNone(found, r.stderr)
            overlap, r_min, _, _, start, closed = (float(found.group(k)) for k in range(1, 7))
            rows = statistics(os.path.join(self.tmp, out))
            previous = float(rows[-1][rows[0].index("max_overlap")])
            self.assertGreater(overlap, r_min)
            self.assertAlmostEqual(start + closed, overlap, delta=1e-5 * r_min)
            self.assertLess(closed, 0.25 * r_min)
            self.assertGreater(start, 0.9 * r_min)
            self.assertLessEqual(start, previous * (1 + 1e-4), (ranks, start, previous))

    def test_nlgs_on_two_ranks_stops_by_its_own_norm(self):
        # 1000 steps of the compaction: NLGS (Quad 1e-4) on two ranks against one.
        args = ["--quiet", "--set", "Solver/Method=nlgs", "--set", "Simulation/End time=2e-6"]
        r = run(["run", "case.prm", "--output", "one"] + args, self.tmp, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = self.run_ranks(2, ["run", "case.prm", "--output", "two"] + args)
        self.assertEqual(r.returncode, 0, r.stderr)
        one, two = (read_json(os.path.join(self.tmp, out, "summary.json")) for out in ("one", "two"))
        self.assertEqual((two["status"], two["steps"], two["solver_method"]), ("complete", 1000, "nlgs"))
        rows = statistics(os.path.join(self.tmp, "two"))
        column = {name: k for k, name in enumerate(rows[0])}
        converged = [row for row in rows[1:] if row[column["solver_converged"]] == "1"]
        self.assertGreater(len(converged), 0.9 * (len(rows) - 1))
        for row in converged:  # NLGS's criterion times its tolerance, at most the tolerance
            self.assertLessEqual(float(row[column["solver_residual"]]), 1e-4)
        # The coupling across the two bands costs a few sweeps, not many.
        self.assertLess(two["solver_iterations_mean"], 1.25 * one["solver_iterations_mean"])
        # The same compaction: the layer's solid fraction at its end.
        last = [float(statistics(os.path.join(self.tmp, out))[-1][column["solid_fraction"]]) for out in ("one", "two")]
        self.assertLess(abs(last[1] - last[0]), 0.01, last)

    def test_apgs_on_two_ranks_solves_to_the_gap_target(self):
        # Ten times the case's step: at APGS's residual target alone the steps' closing errors
        # pass the gap target (0.01 r_min) and grow an overlap to the smallest radius; solving
        # each step to the gap target too, as the serial APGS does, the two ranks complete.
        args = ["--quiet", "--set", "Simulation/Time step=2e-8", "--set", "Simulation/End time=8e-6"]
        r = self.run_ranks(2, ["run", "case.prm", "--output", "aimed"] + args)
        self.assertEqual(r.returncode, 0, r.stderr)
        aimed = read_json(os.path.join(self.tmp, "aimed", "summary.json"))
        self.assertEqual((aimed["status"], aimed["steps"], aimed["gap_target_exceeded"]), ("complete", 400, 0))
        self.assertLessEqual(aimed["gap_violation_max"], 0.01 * aimed["max_overlap"] / aimed["max_overlap_over_min_radius"])
        self.assertLess(aimed["max_overlap_over_min_radius"], 1)
        # Told to stop at a gap of a whole radius, they only flag the steps above the target
        # (and stop at step 279 of 400, an overlap past the radius).
        self.run_ranks(2, ["run", "case.prm", "--output", "flagged", "--set", "Solver/Gap tolerance=1"] + args)
        flagged = read_json(os.path.join(self.tmp, "flagged", "summary.json"))
        self.assertGreater(flagged["gap_target_exceeded"], 10)

    def assert_refused(self, out, entries, message):
        """On two ranks, the case with @p entries set stops with @p message once and writes nothing."""
        args = ["run", "case.prm", "--output", out]
        for entry in entries:
            args += ["--set", entry]
        r = self.run_ranks(2, args)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip().splitlines().count("error: case.prm: " + message), 1, r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, out)), "nothing is written")

    def test_what_is_not_split_is_refused_with_the_remedy(self):
        self.assert_refused("ip", ["Solver/Method=interior-point"],
                            "Solver/Method = interior-point: on 2 MPI ranks the contact solve is APGS's or NLGS's "
                            "sweeps split into bands (docs/scaling.md); set it to apgs or nlgs, or run the case "
                            "without mpirun")
        self.assert_refused("order", ["Solver/Method=nlgs", "Solver/Contact order=random"],
                            "Solver/Contact order and Solver/Streams: on 2 MPI ranks NLGS sweeps each rank's "
                            "contacts in detection order (docs/scaling.md); set them to fixed and 1, or run the "
                            "case without mpirun")

if __name__ == "__main__":
    tribo_cli.main()
