#!/usr/bin/python3
"""The shear cell of tests/cases/test_shear_physics.py (120 discs, 13 us of shear) solved by
NLGS and by a global method stopped at the law residual NLGS reaches (docs/performance.md):
MPRGP and APGS frictionless, and APGS with Coulomb friction 0.3 (against NLGS with it):

- the method converges every step, to its target in the dense sheared layer (while the grains
  rain down, a few lightly loaded contacts make the relative law residual meaningless);
- the kinetic energy balance closes every step of the shear (KE_{i+1} - KE_i =
  h (P_ext + P_contacts); before it, the compaction's speed limit holds the upper wall);
- the lower wall carries P L, and mu equals NLGS's within three combined batch-means
  standard errors (the two runs are two trajectories of one sample);
- the books close: P_dissipated / P_lower_wall within 5 % of 1.

Usage: test_contact_solvers.py PATH/TO/tribo
"""
import concurrent.futures
import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TRIBO = None
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_shear_physics import CASE, P, L  # noqa: E402  the same cell

SHEAR_START = 3e-6  # s, as in CASE


def run(directory, *settings):
    case = os.path.join(directory, "case.prm")
    with open(case, "w") as f:
        f.write(CASE)
    out = os.path.join(directory, "out")
    args = [TRIBO, "run", case, "--output", out, "--quiet"]
    for s in settings:
        args += ["--set", s]
    subprocess.run(args, check=True, capture_output=True, text=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "statistics.csv")) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    return summary["results"] | {k: summary[k] for k in ("status", "solver_method")}, rows


class GlobalMethodAgainstNlgs:
    """One global method (METHOD) against NLGS on the cell, both with Coulomb friction FRICTION."""
    METHOD, FRICTION = None, 0.0

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        law = "Contact law/Friction coefficient=%g" % cls.FRICTION
        nlgs_dir = os.path.join(cls.tmp.name, "nlgs")
        os.makedirs(nlgs_dir)
        cls.nlgs, nlgs_rows = run(nlgs_dir, "Solver/Method=nlgs", law)
        shear = [r["law_residual"] for r in nlgs_rows if r["time"] >= SHEAR_START]
        cls.target = float(np.mean(shear))
        method_dir = os.path.join(cls.tmp.name, cls.METHOD)
        os.makedirs(method_dir)
        cls.method, cls.rows = run(method_dir, "Solver/Method=" + cls.METHOD,
                                   "Solver/Residual target=%.6g" % cls.target, law)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_every_step_reaches_the_target(self):
        self.assertEqual(self.method["solver_method"], self.METHOD)
        self.assertEqual(self.method["status"], "complete")
        self.assertTrue(all(r["solver_converged"] == 1 for r in self.rows))
        # The target is relative to the warm start's mean impulse, the reported residual
        # to the final one's.
        shear = [r["law_residual"] for r in self.rows if r["time"] >= SHEAR_START]
        self.assertGreater(len(shear), 5000)
        self.assertLess(max(shear), 3 * self.target)
        self.assertGreater(self.target, 1e-5)  # NLGS at Quad 1e-3 leaves a real residual

    def test_kinetic_energy_balance_closes_every_step(self):
        h = 2e-9
        loaded = [r for r in self.rows if r["time"] > SHEAR_START + 2 * h]
        for a, b in zip(loaded, loaded[1:]):
            dke = b["kinetic_energy"] - a["kinetic_energy"]
            rhs = h * (b["power_external"] + b["power_contacts"])
            scale = abs(dke) + h * (abs(b["power_external"]) + abs(b["power_contacts"]))
            self.assertLessEqual(abs(dke - rhs), 1e-6 * scale + 1e-30, "step %d" % b["step"])

    def test_load_and_friction_as_nlgs(self):
        for s in (self.nlgs, self.method):
            self.assertLess(abs(s["normal_force_mean"] / (P * L) - 1),
                            max(0.02, 3 * s["normal_force_stderr"] / (P * L)))
        combined = np.hypot(self.nlgs["mu_stderr"], self.method["mu_stderr"])
        self.assertGreater(self.method["mu_mean"], 0.02)
        self.assertLess(abs(self.method["mu_mean"] - self.nlgs["mu_mean"]), 3 * combined,
                        "mu %.4f +/- %.4f (%s) against %.4f +/- %.4f (nlgs)" % (
                            self.method["mu_mean"], self.method["mu_stderr"], self.METHOD,
                            self.nlgs["mu_mean"], self.nlgs["mu_stderr"]))

    def test_power_balance(self):
        self.assertLess(abs(self.method["power_balance_ratio"] - 1), 0.05)


class MprgpAgainstNlgs(GlobalMethodAgainstNlgs, unittest.TestCase):
    METHOD = "mprgp"


class ApgsAgainstNlgs(GlobalMethodAgainstNlgs, unittest.TestCase):
    METHOD = "apgs"


class FrictionalApgsAgainstNlgs(GlobalMethodAgainstNlgs, unittest.TestCase):
    """Coulomb friction 0.3 between grains and at the walls: APGS solves it itself."""
    METHOD, FRICTION = "apgs", 0.3

    def test_friction_raises_mu(self):
        # Friction between grains raises the layer's friction well above the frictionless
        # cell's (about 0.1 on this cell, tests/cases/test_shear_physics.py).
        self.assertGreater(self.nlgs["mu_mean"], 0.15)
        self.assertGreater(self.method["mu_mean"], 0.15)


if __name__ == "__main__":
    TRIBO = os.path.abspath(sys.argv.pop(1))
    unittest.main()
