"""Checkpoints and `tribo run CASE.prm --resume DIR` for the scenes that run their own
loop (app/particle_scenes.h), as test_resume.py does for the NSCD scenes:

- sph_slider (2D, small; the block starts sliding during the run, which switches the
  damping) and mlp_compression (at a finite temperature, so the Langevin noise must go on
  with the same random numbers; with density maps): a run killed with SIGKILL after a
  checkpoint and resumed with --resume gives the same statistics.csv byte for byte (the
  same doubles: bit-identical), the same results.h5 statistics, scene tables, snapshot
  index and summary results as the run done in one go, and removes its checkpoint;
- a resumption that changes an entry other than Solver/*, Output/* or Simulation/End time
  (a material entry) is refused with exit code 2 and a message naming the entry, and
  leaves the checkpoint, from which the run then goes on;
- sph_plate stopped by SIGTERM (status "interrupted", exit 143, a checkpoint of the last
  step) and resumed with a later Simulation/End time repeats, bit for bit, the run done in
  one go to that end time.

Usage: /usr/bin/python3 test_resume_particles.py /path/to/tribo
"""

import filecmp
import os
import signal
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import TempDirTestCase, read_json, read_pvd, run, run_and_stop, write_prm  # noqa: E402

#: A small 2D slider (cases/sph_slider/quick.prm, shorter): sliding starts at 1e-4 s.
SPH_CASE = {
    "Simulation": {"Scene": "sph_slider", "End time": "2.5e-4"},
    "SPH slider": {"Dimension": "2", "Particle spacing": "5e-4", "Block size": "4e-3, 1, 2e-3",
                   "Substrate size": "8e-3, 1, 1.5e-3", "Pressure": "1e8", "Pressure ramp time": "3e-5",
                   "Slide start": "1e-4", "Sliding velocity": "1", "Driven layers": "2", "Gamma": "1e6",
                   "Statistics interval": "2e-6", "Field interval": "5e-5"},
    "Output": {"Checkpoint step interval": "200"},
}

#: A 20 x 10 slab pressed at 1e8 Pa with thermal noise (k_B T > 0) and density maps.
MLP_CASE = {
    "Simulation": {"Scene": "mlp_compression", "End time": "8e-6"},
    "MLP": {"Return force amplitude": "20", "Damping": "0.005", "Thermal energy": "1e-8",
            "Time step": "2e-10", "Statistics interval": "10", "Snapshot interval": "2000"},
    "MLP compression": {"Columns": "20", "Rows": "10", "Pressure": "1e8", "Density maps": "3"},
    "Output": {"Plots": "false", "Checkpoint step interval": "1000"},
}


#: The cantilever plate (cases/sph_slider/plate.prm), a checkpoint every 100 steps.
PLATE_CASE = {
    "Simulation": {"Scene": "sph_plate", "End time": "6e-4"},
    "SPH plate": {"Length": "0.2", "Thickness": "0.02", "Tip velocity": "0.05"},
    "Output": {"Checkpoint step interval": "100"},
}


class ResumeParticles(TempDirTestCase):
    def assert_same_run(self, ref, resumed, series="particles", tables=()):
        """The resumed run in @p resumed repeats the run in one go in @p ref exactly."""
        a, b = os.path.join(self.tmp, ref), os.path.join(self.tmp, resumed)
        for name in ("statistics.csv",) + tuple(t + ".csv" for t in tables):
            self.assertTrue(filecmp.cmp(os.path.join(a, name), os.path.join(b, name), shallow=False),
                            "%s differs between the run in one go and the resumed one" % name)
        sa, sb = read_json(os.path.join(a, "summary.json")), read_json(os.path.join(b, "summary.json"))
        self.assertEqual((sa["status"], sb["status"]), ("complete", "complete"))
        self.assertEqual(sa["results"], sb["results"])
        for key in ("steps", "simulated_time", "n_field_snapshots"):
            self.assertEqual(sa[key], sb[key], key)
        with h5py.File(os.path.join(a, "results.h5"), "r") as fa, \
                h5py.File(os.path.join(b, "results.h5"), "r") as fb:
            self.assertEqual(sorted(fa["statistics"]), sorted(fb["statistics"]))
            for name in fa["statistics"]:
                np.testing.assert_array_equal(fa["statistics"][name][()], fb["statistics"][name][()],
                                              err_msg=name)
        self.assertEqual(read_pvd(os.path.join(a, "fields", series + ".pvd")),
                         read_pvd(os.path.join(b, "fields", series + ".pvd")))
        self.assertFalse(os.path.exists(os.path.join(b, "checkpoint.bin")),
                         "a complete run removes its checkpoint")
        self.assertFalse(os.path.exists(os.path.join(a, "checkpoint.bin")),
                         "a complete run removes its checkpoint")
        with open(os.path.join(b, "log.txt")) as f:
            log = f.read()
        self.assertIn("resuming from out/checkpoint.bin", log)
        self.assertIn("resumed at step ", log)
        return sa

    def assert_change_refused(self, entry, value, saved):
        """--resume with @p entry = @p value (the checkpoint has @p saved): exit 2, the
        message names the entry, the checkpoint stays."""
        r = run(["run", "case.prm", "--resume", "out", "--quiet", "--set", "%s=%s" % (entry, value)],
                self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip(),
                         "error: --resume out: entry '%s' is '%s' in the case but '%s' in the "
                         "checkpoint; a resumed run may change only Solver/*, Output/*, "
                         "Simulation/End time, Simulation/Most substeps, Simulation/Most substeps on retake and "
                         "Shear cell/Upper body prediction depth"
                         % (entry, value, saved))
        self.assertTrue(os.path.exists(os.path.join(self.tmp, "out", "checkpoint.bin")),
                        "a refused resumption keeps the checkpoint")

    def kill_refuse_resume(self, case, entry, value, saved):
        """The reference run in one go into ref/, then the run into out/ killed after a
        checkpoint, a refused resumption changing @p entry, and the resumption."""
        write_prm(os.path.join(self.tmp, "case.prm"), case)
        r = run(["run", "case.prm", "--output", "ref", "--quiet"], self.tmp, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        run_and_stop(self, self.tmp, "case.prm", "out", signal.SIGKILL)
        self.assertEqual(read_json(os.path.join(self.tmp, "out", "summary.json"))["status"], "running",
                         "a killed run leaves its summary as it was")
        self.assert_change_refused(entry, value, saved)
        r = run(["run", "case.prm", "--resume", "out", "--quiet"], self.tmp, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_sph_slider_sigkill_then_resume_is_bit_identical(self):
        self.kill_refuse_resume(SPH_CASE, "SPH slider/Material", "basalt", "granite")
        s = self.assert_same_run("ref", "out")
        self.assertGreater(s["results"]["window_rows"], 0, "the run reaches the sliding phase")

    def test_mlp_compression_sigkill_then_resume_is_bit_identical(self):
        self.kill_refuse_resume(MLP_CASE, "MLP/Thermal energy", "2e-8", "1e-8")
        self.assert_same_run("ref", "out",
                             tables=("density_maps", "density_histograms", "density_snapshots"))

    def test_sph_plate_sigterm_then_resume_to_a_later_end_time(self):
        write_prm(os.path.join(self.tmp, "case.prm"), PLATE_CASE)
        r = run(["run", "case.prm", "--output", "ref", "--quiet", "--set", "Simulation/End time=8e-4"],
                self.tmp, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        run_and_stop(self, self.tmp, "case.prm", "out", signal.SIGTERM, after_checkpoint_s=0.1)
        s = read_json(os.path.join(self.tmp, "out", "summary.json"))
        self.assertEqual((s["status"], s["signal"]), ("interrupted", signal.SIGTERM))
        self.assertLess(s["simulated_time"], 6e-4)
        self.assertTrue(os.path.exists(os.path.join(self.tmp, "out", "checkpoint.bin")),
                        "SIGTERM writes a checkpoint")
        r = run(["run", "case.prm", "--resume", "out", "--quiet", "--set", "Simulation/End time=8e-4"],
                self.tmp, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_same_run("ref", "out")
        with open(os.path.join(self.tmp, "out", "log.txt")) as f:
            self.assertIn("; changed: Simulation/End time 6e-4 -> 8e-4", f.read())


if __name__ == "__main__":
    tribo_cli.main()
