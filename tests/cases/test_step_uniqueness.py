#!/usr/bin/python3
"""One step of the shear cell of tests/cases/test_shear_physics.py (120 discs), solved tight
by three methods that share no code: the interior point (1e-10), APGS (1e-8) and NLGS
(1e-8). The packing is hyperstatic, so its impulses need not be unique; its velocities are,
and so, with frictionless IQS contacts, are the walls' forces: two minimisers of the step's
quadratic programme differ by a self-stress s with W s = 0 and b.s = 0, whose work on the
step's velocities, F_x V (the only wall velocity that is imposed and not zero), is then zero
(docs/validation.md, "What the friction of this model is"). The test holds the model to it:

- each solve reaches its target;
- the step's mu and the lower wall's normal force agree with the interior point's within
  1e-4 (APGS) and 5e-4 (NLGS, whose sweeps stall sooner), relative;
- every grain's velocity agrees within 1e-4 V.

With Coulomb friction 0.3 between the grains nothing proves the impulses' or the force's
uniqueness (the law is not associated); the two methods that solve it, APGS and NLGS at
1e-8, must still agree on that step within the same tolerances (measured: 1.3e-5 in mu,
2e-6 V in the velocities).

Each solve goes on from one sheared state of its law (Shear cell/Initial state, 4 us of
shear), from a cold start (no warm impulses), so nothing but the solve differs.

Usage: test_step_uniqueness.py PATH/TO/tribo
"""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TRIBO = None
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_shear_physics import CASE, V  # noqa: E402  the same cell

STATE_TIME = 7e-6  # s: 4 us after Shear start
H = 2e-9           # s, the cell's time step
SOLVES = {
    "interior-point": ["Solver/Method=interior-point", "Solver/Residual target=1e-10"],
    "apgs": ["Solver/Method=apgs", "Solver/Residual target=1e-8", "Solver/Maximum iterations=100000"],
    "nlgs": ["Solver/Method=nlgs", "Solver/Norm=Quad", "Solver/Tolerance=1e-8",
             "Solver/Maximum iterations=300000"],
}


FRICTION = "Contact law/Friction coefficient=0.3"


def one_step(directory, settings, state="state"):
    out = os.path.join(directory, state + "-" + settings[0].split("=")[1])
    args = [TRIBO, "run", os.path.join(directory, "case.prm"), "--output", out, "--quiet",
            "--set", "Shear cell/Initial state=" + os.path.join(directory, state),
            "--set", "Simulation/End time=%.17g" % (STATE_TIME + H)]
    for s in settings + ([FRICTION] if state == "frictional" else []):
        args += ["--set", s]
    subprocess.run(args, check=True, timeout=300)
    with open(os.path.join(out, "statistics.csv")) as f:
        last = list(csv.DictReader(f))[-1]
    with open(os.path.join(out, "sample_final.csv")) as f:
        grains = [r for r in csv.DictReader(f) if r["body"] == "grain"]
    velocities = np.array([[float(r["vx"]), float(r["vy"]), float(r["r"]) * float(r["spin"])] for r in grains])
    return last, velocities


class StepUniqueness(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        with open(os.path.join(cls.tmp.name, "case.prm"), "w") as f:
            f.write(CASE)
        for state, extra in (("state", []), ("frictional", ["--set", FRICTION])):
            subprocess.run([TRIBO, "run", os.path.join(cls.tmp.name, "case.prm"), "--output",
                            os.path.join(cls.tmp.name, state), "--quiet",
                            "--set", "Simulation/End time=%g" % STATE_TIME] + extra, check=True, timeout=300)
        cls.steps = {name: one_step(cls.tmp.name, settings) for name, settings in SOLVES.items()}
        cls.frictional = {name: one_step(cls.tmp.name, SOLVES[name], "frictional") for name in ("apgs", "nlgs")}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_every_solve_reaches_its_target(self):
        for name, target in (("interior-point", 1e-10), ("apgs", 1e-8), ("nlgs", 1e-7)):
            last, _ = self.steps[name]
            self.assertLessEqual(float(last["law_residual"]), target, name)

    def test_the_lower_wall_force_is_the_same_for_every_method(self):
        ip, _ = self.steps["interior-point"]
        mu_ip, normal_ip = float(ip["mu"]), float(ip["lower_wall_normal_force"])
        self.assertGreater(mu_ip, 0.05)  # the sheared layer carries a friction worth comparing
        for name, tolerance in (("apgs", 1e-4), ("nlgs", 5e-4)):
            last, _ = self.steps[name]
            self.assertLess(abs(float(last["mu"]) / mu_ip - 1), tolerance, name)
            self.assertLess(abs(float(last["lower_wall_normal_force"]) / normal_ip - 1), tolerance, name)

    def test_the_velocities_are_the_same_for_every_method(self):
        _, reference = self.steps["interior-point"]
        for name in ("apgs", "nlgs"):
            _, velocities = self.steps[name]
            self.assertEqual(velocities.shape, reference.shape)
            self.assertLess(np.abs(velocities - reference).max(), 1e-4 * V, name)

    def test_with_friction_apgs_and_nlgs_give_one_step(self):
        (apgs, v_apgs), (nlgs, v_nlgs) = self.frictional["apgs"], self.frictional["nlgs"]
        for last in (apgs, nlgs):
            self.assertLessEqual(float(last["law_residual"]), 1e-7)
        self.assertGreater(float(apgs["mu"]), 0.02)
        self.assertLess(abs(float(nlgs["mu"]) / float(apgs["mu"]) - 1), 1e-4)
        self.assertLess(np.abs(v_nlgs - v_apgs).max(), 1e-4 * V)


if __name__ == "__main__":
    TRIBO = sys.argv.pop(1)
    unittest.main()
