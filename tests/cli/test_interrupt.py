"""An interrupted run (SIGTERM, SIGINT) ends cleanly: exit 128+N, outputs that
hold the steps done (the shear scene's profiles.csv and, with Output/Plots,
its PNG plots included), summary.json status "interrupted", results.h5
complete = 0, no NAME.tmp left behind.

Usage: /usr/bin/python3 test_interrupt.py /path/to/tribo
"""

import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import (PLOTS, PROFILE_COLUMNS, TempDirTestCase, read_csv, read_json,  # noqa: E402
                       read_png, read_pvd, tmp_files, write_prm)

#: A shear run far too long to finish during the test (5e5 steps): 60 discs,
#: sliding from step 100 on, a profile sample every 5 steps.
LONG = {
    "Simulation": {"Scene": "shear", "Time step": "2e-9", "End time": "1e-3"},
    "Shear cell": {"Number of discs": "60", "Length": "1.2e-5", "Wall discs": "0",
                   "Pressure ramp time": "1e-7", "Shear start": "2e-7", "Profile samples": "100000"},
    "Output": {"Statistics interval": "1", "Field interval": "0", "Plots": "false"},
}


def with_changes(changes):
    """LONG with {"Subsection/Entry": value} changes."""
    sections = {k: dict(v) for k, v in LONG.items()}
    for path, value in changes.items():
        section, entry = path.split("/")
        sections[section][entry] = value
    return sections


class Interrupt(TempDirTestCase):
    def start(self, sections):
        write_prm(os.path.join(self.tmp, "long.prm"), sections)
        self.out = os.path.join(self.tmp, "out")
        self.proc = subprocess.Popen([tribo_cli.TRIBO, "run", "long.prm", "--output", "out", "--quiet"],
                                     cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     universal_newlines=True)
        self.addCleanup(self.stop)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.communicate()

    def wait_until_stepping(self, timeout=20.0):
        """Wait for the time loop (log.txt has the 'scene' line), then let it step ~1 s."""
        log = os.path.join(self.out, "log.txt")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.assertIsNone(self.proc.poll(), "tribo ended before it was interrupted")
            if os.path.exists(log):
                with open(log) as f:
                    if "\nscene " in f.read():
                        break
            time.sleep(0.05)
        else:
            self.fail("tribo did not start stepping within %g s" % timeout)
        self.assertEqual(read_json(os.path.join(self.out, "summary.json"))["status"], "running")
        time.sleep(1.0)
        self.assertIsNone(self.proc.poll(), "tribo ended before it was interrupted")

    def interrupt(self, sig):
        self.proc.send_signal(sig)
        stdout, stderr = self.proc.communicate(timeout=60)
        return self.proc.returncode, stderr

    def check_interrupted(self, sig):
        code, stderr = self.interrupt(sig)
        self.assertEqual(code, 128 + sig, stderr)
        s = read_json(os.path.join(self.out, "summary.json"))
        self.assertEqual(s["status"], "interrupted")
        self.assertEqual(s["signal"], sig)
        self.assertGreater(s["steps"], 0)
        self.assertLess(s["steps"], s["steps_planned"])
        self.assertAlmostEqual(s["simulated_time"], s["steps"] * s["time_step"], delta=1e-9 * s["simulated_time"])

        _, st = read_csv(os.path.join(self.out, "statistics.csv"))
        self.assertEqual(int(st["step"][-1]), s["steps"], "the last row is the last step done")

        with open(os.path.join(self.out, "log.txt")) as f:
            log = f.read()
        self.assertIn("status interrupted: %d steps" % s["steps"], log)
        self.assertIn("interrupted by signal %d" % sig, log)

        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            self.assertEqual(f.attrs["steps"], s["steps"])
            np.testing.assert_array_equal(f["statistics/step"][()], st["step"])

        records = read_pvd(os.path.join(self.out, "fields", "discs.pvd"))
        self.assertEqual(len(records), s["n_field_snapshots"])
        self.assertAlmostEqual(records[-1][0], s["simulated_time"], delta=1e-9 * s["simulated_time"])
        self.assertEqual(tmp_files(self.out), [], "no NAME.tmp may be left behind")

        # The shear results and profiles of the steps done (sliding from step 100 on).
        r = s["results"]
        self.assertIs(r["sliding"], True)
        self.assertEqual(r["averaging_start"], r["steady_state_start"])
        header, p = read_csv(os.path.join(self.out, "profiles.csv"))
        self.assertEqual(header, PROFILE_COLUMNS)
        self.assertGreater(r["profile_samples_in_steady_state"], 0)
        np.testing.assert_array_equal(p["n_samples"], r["profile_samples_in_steady_state"])
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(f["profiles"].attrs["n_rows"], len(p["layer"]))
            for name in header:
                np.testing.assert_array_equal(f["profiles"][name][()], p[name], err_msg=name)
        return s, st

    def test_sigterm(self):
        self.start(LONG)
        self.wait_until_stepping()
        self.check_interrupted(signal.SIGTERM)

    def test_sigint(self):
        """Interrupted with Output/Plots = true: the plots of the steps done are made."""
        self.start(with_changes({"Output/Plots": "true"}))
        self.wait_until_stepping()
        self.check_interrupted(signal.SIGINT)
        for name in PLOTS:
            image = read_png(self, os.path.join(self.out, name))
            self.assertGreater(min(image.shape[:2]), 100, name)
        with open(os.path.join(self.out, "log.txt")) as f:
            self.assertNotIn("warning: the plots could not be made", f.read())

    def test_sigterm_sparse_statistics(self):
        """Rows only every 10^6 steps: the interrupted run must still end with the row
        of its last step (the run does about 10^4 steps before the signal)."""
        self.start(with_changes({"Simulation/End time": "1e-2", "Output/Statistics interval": "1000000"}))
        self.wait_until_stepping()
        code, stderr = self.interrupt(signal.SIGTERM)
        self.assertEqual(code, 128 + signal.SIGTERM, stderr)
        s = read_json(os.path.join(self.out, "summary.json"))
        _, st = read_csv(os.path.join(self.out, "statistics.csv"))
        self.assertEqual(len(st["step"]), 1, "a row for the last step done")
        self.assertEqual(int(st["step"][-1]), s["steps"])


if __name__ == "__main__":
    tribo_cli.main()
