"""The output directory of `tribo run` (docs/outputs.md), checked by value:
statistics.csv, results.h5, summary.json, the VTU snapshots and their .pvd
indices, for a small ELAS collision and a small compaction; a failing run.

Usage: /usr/bin/python3 test_outputs.py /path/to/tribo
"""

import math
import os
import re
import sys
import tempfile
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import (COMMON_COLUMNS, SCENE_COLUMNS, TempDirTestCase, decode_vtu,  # noqa: E402
                       read_csv, read_json, read_pvd, read_vtu_with_vtk, run, tmp_files,
                       write_prm)

FILES = ["fields", "log.txt", "original.prm", "parameters.prm", "results.h5",
         "statistics.csv", "summary.json"]

# Float32 in the VTU files: relative precision of the stored values.
F32 = 2e-7


class RunOnce:
    """Mixin: run the case SECTIONS once for the whole class, in a fresh temporary
    directory, and check what every scene shares."""

    SECTIONS = None

    @classmethod
    def setUpClass(cls):
        cls._tmp = tempfile.TemporaryDirectory(prefix="tribo-cli-")
        cls.tmp = cls._tmp.name
        cls.case = os.path.join(cls.tmp, "case.prm")
        write_prm(cls.case, cls.SECTIONS, preamble="# written by tests/cli/test_outputs.py")
        cls.out = os.path.join(cls.tmp, "out")
        cls.result = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=cls.tmp)
        cls.summary = read_json(os.path.join(cls.out, "summary.json"))
        cls.header, cls.stats = read_csv(os.path.join(cls.out, "statistics.csv"))
        cls.fields = os.path.join(cls.out, "fields")

    @classmethod
    def tearDownClass(cls):
        cls._tmp.cleanup()

    # --- checks shared by the scenes -------------------------------------

    def test_exit_and_files(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        self.assertEqual(self.result.stdout, "", "--quiet prints nothing")
        self.assertEqual(sorted(os.listdir(self.out)), FILES)
        self.assertEqual(tmp_files(self.out), [], "no NAME.tmp may be left behind")

    def test_statistics_header(self):
        """The documented columns, in order; a scene may append new ones (which
        test_docs_cover_outputs then requires to be documented)."""
        expected = COMMON_COLUMNS + SCENE_COLUMNS[self.summary["scene"]]
        self.assertEqual(self.header[:len(expected)], expected)
        self.assertEqual(len(set(self.header)), len(self.header), "column names are unique")

    def test_summary_agrees_with_statistics(self):
        s, st = self.summary, self.stats
        self.assertEqual(s["status"], "complete")
        self.assertEqual(s["case"], "case.prm")
        self.assertEqual(s["steps"], int(st["step"][-1]))
        np.testing.assert_array_equal(st["step"], np.arange(1, s["steps"] + 1),
                                      "Statistics interval 1: one row per step")
        np.testing.assert_allclose(st["time"], st["step"] * s["time_step"], rtol=1e-12)
        self.assertAlmostEqual(s["simulated_time"], s["steps"] * s["time_step"], delta=1e-12 * s["simulated_time"])
        self.assertEqual(s["nlgs_iterations_total"], int(st["nlgs_iterations"].sum()))
        self.assertEqual(s["nlgs_iterations_max"], int(st["nlgs_iterations"].max()))
        self.assertAlmostEqual(s["nlgs_iterations_mean"], st["nlgs_iterations"].mean(), places=9)
        self.assertEqual(s["nlgs_non_converged_steps"], int((st["nlgs_converged"] == 0).sum()))
        self.assertEqual(s["nlgs_residual_max"], st["nlgs_residual"].max())
        self.assertEqual(s["max_overlap"], st["max_overlap"].max())
        self.assertTrue(set(np.unique(st["nlgs_converged"])) <= {0.0, 1.0})
        self.assertTrue(np.all(st["n_active_contacts"] <= st["n_contacts"]))
        self.assertTrue(np.all(st["max_overlap"] >= 0))
        self.assertGreater(s["wall_time"], 0)
        self.assertEqual(s["n_field_snapshots"], len(read_pvd(os.path.join(self.fields, "discs.pvd"))))

    def test_energy_balance(self):
        """Sum of h (power_contacts + power_external) is the change of kinetic energy
        (exact for the Moreau-Jean update, rows at every step)."""
        st, h = self.stats, self.summary["time_step"]
        ke0 = self.initial_kinetic_energy()
        work = np.cumsum(h * (st["power_contacts"] + st["power_external"]))
        scale = max(np.abs(st["kinetic_energy"]).max(), ke0)
        np.testing.assert_allclose(work, st["kinetic_energy"] - ke0, rtol=0, atol=1e-9 * scale)

    def test_results_h5(self):
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["complete"], 1)
            self.assertEqual(f.attrs["steps"], self.summary["steps"])
            self.assertEqual(f.attrs["time_step"], self.summary["time_step"])
            self.assertEqual(f.attrs["simulated_time"], self.summary["simulated_time"])
            self.assertEqual(f.attrs["wall_time"], self.summary["wall_time"])
            g = f["statistics"]
            self.assertEqual(sorted(g.keys()), sorted(self.header))
            self.assertEqual(g.attrs["n_rows"], len(self.stats["step"]))
            for name in self.header:
                self.assertEqual(g[name].shape, self.stats[name].shape, name)
                np.testing.assert_allclose(g[name][()], self.stats[name], rtol=0, atol=0,
                                           err_msg=name)  # the CSV has full precision
            p = f["parameters"].attrs
            for section, entries in self.SECTIONS.items():
                for entry, value in entries.items():
                    self.assertEqual(p["%s/%s" % (section, entry)], value)
            # Every declared entry is there, the ones not set at their defaults.
            r = run(["params"], cwd=self.tmp)
            declared = []
            section = None
            for line in r.stdout.splitlines():
                m = re.match(r"\s*subsection (.*)$", line)
                if m:
                    section = m.group(1).strip()
                m = re.match(r"\s*set (.*?) = (.*)$", line)
                if m:
                    declared.append(("%s/%s" % (section, m.group(1).strip()), m.group(2).strip()))
            self.assertEqual(sorted(p.keys()), sorted(k for k, _ in declared))
            for key, default in declared:
                if key.split("/")[1] not in self.SECTIONS.get(key.split("/")[0], {}):
                    self.assertEqual(p[key], default, key)

    def test_prm_copies(self):
        with open(self.case) as a, open(os.path.join(self.out, "original.prm")) as b:
            self.assertEqual(a.read(), b.read(), "original.prm is the case file as read")
        r = run(["check", os.path.join(self.out, "parameters.prm")], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.out, "parameters.prm")) as f:
            text = f.read()
        for section, entries in self.SECTIONS.items():
            for entry, value in entries.items():
                self.assertRegex(text, r"set %s\s*= %s\b" % (re.escape(entry), re.escape(value)))

    def test_log(self):
        with open(os.path.join(self.out, "log.txt")) as f:
            lines = f.read().splitlines()
        self.assertEqual(lines[0], "tribo run case.prm -> out")
        self.assertTrue(lines[1].startswith("scene %s: " % self.summary["scene"]), lines[1])
        self.assertTrue(lines[-1].startswith("status complete: %d steps" % self.summary["steps"]), lines[-1])

    def test_pvd_indices(self):
        times_expected = self.snapshot_times()
        for kind in ("discs", "contacts"):
            records = read_pvd(os.path.join(self.fields, kind + ".pvd"))
            files = [f for _, f in records]
            times = [t for t, _ in records]
            on_disk = sorted(f for f in os.listdir(self.fields) if f.startswith(kind + "_"))
            self.assertEqual(files, on_disk, "%s.pvd lists every %s_NNNNN.vtu, in order" % (kind, kind))
            self.assertEqual(files, ["%s_%05d.vtu" % (kind, i) for i in range(len(files))])
            self.assertTrue(all(b > a for a, b in zip(times, times[1:])), times)
            np.testing.assert_allclose(times, times_expected, rtol=1e-10, atol=0)

    def test_disc_snapshots(self):
        """Every discs VTU reads with VTK: one vertex per disc, the documented arrays."""
        n = self.summary["n_discs"]
        for t, name in read_pvd(os.path.join(self.fields, "discs.pvd")):
            v = read_vtu_with_vtk(self, os.path.join(self.fields, name))
            self.assertEqual(v["n_points"], n, name)
            self.assertEqual(v["n_cells"], n, name)
            self.assertEqual(set(v["cell_types"]), {1}, "VTK_VERTEX cells")
            self.assertEqual(sorted(v["point_data"]), ["body", "radius", "spin", "velocity"])
            self.assertEqual(v["point_data"]["velocity"].shape, (n, 3))
            np.testing.assert_array_equal(v["point_data"]["velocity"][:, 2], 0)
            np.testing.assert_array_equal(v["points"][:, 2], 0)

    def test_contact_snapshots_decoded(self):
        """Contacts VTU by value, decoded without VTK: one line per active contact."""
        for t, name in read_pvd(os.path.join(self.fields, "contacts.pvd")):
            d = decode_vtu(os.path.join(self.fields, name))
            self.assertEqual(d["n_points"], 2 * d["n_cells"], name)
            self.assertEqual(sorted(d["point_data"]), ["gap", "normal_force", "tangential_force"])
            if d["connectivity"] is not None:
                np.testing.assert_array_equal(d["connectivity"], np.arange(2 * d["n_cells"]))
            f = d["point_data"]["normal_force"].ravel()
            np.testing.assert_array_equal(f[0::2], f[1::2], "one value per contact, on both ends")
            self.assertTrue(np.all(f >= 0), "no cohesion: compressive forces only (%s)" % name)
        last = decode_vtu(os.path.join(self.fields, name))
        self.assertEqual(last["n_cells"], int(self.stats["n_active_contacts"][-1]),
                         "the last snapshot is written after the last step")

    def test_contact_snapshots_read_with_vtk(self):
        for t, name in read_pvd(os.path.join(self.fields, "contacts.pvd")):
            v = read_vtu_with_vtk(self, os.path.join(self.fields, name))
            self.assertEqual(set(v["cell_types"]) - {3}, set(), "VTK_LINE cells")
            self.assertTrue(np.all(v["point_data"]["normal_force"] >= 0))
        self.assertEqual(v["n_cells"], int(self.stats["n_active_contacts"][-1]))

    def test_docs_cover_outputs(self):
        """docs/outputs.md names every column, summary key and VTU array (in backquotes)."""
        with open(tribo_cli.OUTPUTS_MD) as f:
            doc = f.read()
        names = list(self.header) + list(self.summary) + list(self.summary["results"])
        names += ["radius", "velocity", "spin", "body", "normal_force", "tangential_force", "gap",
                  "complete", "n_rows"]
        missing = [n for n in names if "`%s`" % n not in doc]
        self.assertEqual(missing, [], "undocumented in docs/outputs.md")


class Collision(RunOnce, unittest.TestCase):
    """Two discs, ELAS without cohesion, dt*/dt = 100."""

    D, RHO, V, GAP, K = 1.2e-6, 7800.0, 2.0, 1e-10, 1e10
    SECTIONS = {
        "Simulation": {"Scene": "collision", "End time": "1e-6"},
        "Contact law": {"Law": "ELAS", "Stiffness": "1e10", "Detection distance": "1e-9"},
        "Solver": {"Check interval": "1"},
        "Collision": {"Diameter": "1.2e-6", "Density": "7800", "Impact velocity": "2",
                      "Initial gap": "1e-10", "Time step ratio": "100"},
    }

    @property
    def mass(self):
        return self.RHO * math.pi * (self.D / 2) ** 2

    def initial_kinetic_energy(self):
        return 2 * 0.5 * self.mass * (self.V / 2) ** 2

    def snapshot_times(self):
        return [0.0, self.summary["simulated_time"]]

    def test_time_step_from_ratio(self):
        dt_star = math.sqrt(0.5 * self.mass / self.K)
        r = self.summary["results"]
        self.assertAlmostEqual(r["effective_mass"] / (0.5 * self.mass), 1, places=12)
        self.assertAlmostEqual(r["dt_star"] / dt_star, 1, places=12)
        self.assertAlmostEqual(self.summary["time_step"] / (dt_star / 100), 1, places=12)
        self.assertAlmostEqual(r["time_step_ratio"], 100, places=9)
        self.assertLess(self.summary["steps"], self.summary["steps_planned"], "stopped once separated")

    def test_contact_duration_and_energy(self):
        r = self.summary["results"]
        elastic = math.pi * math.sqrt(0.5 * self.mass / self.K)
        self.assertAlmostEqual(r["elastic_contact_duration"] / elastic, 1, places=12)
        self.assertLess(abs(r["contact_duration"] / elastic - 1), 0.02)
        contact_steps = int((self.stats["normal_force"] != 0).sum())
        self.assertAlmostEqual(r["contact_duration"], contact_steps * self.summary["time_step"],
                               delta=1e-12 * elastic)
        self.assertGreaterEqual(r["energy_loss"], 0)
        self.assertLess(r["energy_loss"], 0.05)
        ke0 = self.initial_kinetic_energy()
        self.assertAlmostEqual(r["kinetic_energy_initial"] / ke0, 1, places=12)
        self.assertAlmostEqual(r["energy_loss"], 1 - r["kinetic_energy_final"] / ke0, places=12)
        self.assertAlmostEqual(self.stats["energy_change"][-1], -r["energy_loss"], places=12)
        self.assertAlmostEqual(self.stats["kinetic_energy"][-1], r["kinetic_energy_final"], places=20)
        self.assertTrue(r["separated"])
        self.assertEqual(r["escape_velocity"], 0)

    def test_collision_columns(self):
        st = self.stats
        h = self.summary["time_step"]
        # Before contact the discs approach at V: relative velocity -V, gap closing by V h a step.
        self.assertEqual(st["relative_normal_velocity"][0], -self.V)
        self.assertAlmostEqual(st["gap"][0], self.GAP - self.V * h, delta=1e-6 * self.GAP)
        self.assertEqual(st["normal_force"][0], 0)
        # No cohesion: the force on disc 1 along +x is never negative; it is positive in contact.
        self.assertTrue(np.all(st["normal_force"] >= 0))
        self.assertGreater(st["normal_force"].max(), 0)
        # The discs overlap during the contact and separate at the end.
        self.assertLess(st["gap"].min(), 0)
        self.assertAlmostEqual(st["gap"][-1], self.summary["results"]["final_gap"], places=20)
        self.assertGreater(st["gap"][-1], 1e-9, "farther apart than the detection distance")
        vout = st["relative_normal_velocity"][-1]
        self.assertGreater(vout, 0, "separating")
        self.assertAlmostEqual(self.summary["results"]["restitution_coefficient"], vout / self.V, places=12)
        # Two free bodies, no loads: all the power is contact power.
        np.testing.assert_array_equal(st["power_external"], 0)
        np.testing.assert_allclose(st["power_free"], st["power_contacts"], rtol=1e-12, atol=0)
        self.assertEqual(self.summary["n_bodies"], 2)
        self.assertEqual(self.summary["n_discs"], 2)

    def test_disc_values(self):
        pvd = read_pvd(os.path.join(self.fields, "discs.pvd"))
        first = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[0][1]))
        pd = first["point_data"]
        self.assertEqual(first["n_points"], self.summary["n_discs"])
        np.testing.assert_allclose(pd["radius"].ravel(), [self.D / 2] * 2, rtol=F32)
        np.testing.assert_allclose(pd["velocity"], [[self.V / 2, 0, 0], [-self.V / 2, 0, 0]], rtol=F32)
        np.testing.assert_array_equal(pd["body"].ravel(), [0, 1])
        np.testing.assert_array_equal(pd["spin"].ravel(), [0, 0])
        np.testing.assert_allclose(first["points"][:, :2], [[0, 0], [self.D + self.GAP, 0]], rtol=F32, atol=0)
        last = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[-1][1]))
        v = last["point_data"]["velocity"]
        self.assertAlmostEqual((v[1, 0] - v[0, 0]) / self.stats["relative_normal_velocity"][-1], 1, delta=1e-6)
        gap = last["points"][1, 0] - last["points"][0, 0] - self.D
        self.assertAlmostEqual(gap / self.stats["gap"][-1], 1, delta=1e-3)  # float32 positions


class Compaction(RunOnce, unittest.TestCase):
    """60 discs pressed between rough walls, IQS without cohesion."""

    N, D, S, L, RHO, P, THICK, RAMP = 60, 1.2e-6, 0.2, 1.2e-5, 7800.0, 1e8, 1.5e-4, 50
    SECTIONS = {
        "Simulation": {"Scene": "compaction", "Time step": "2e-9", "End time": "4e-7"},
        "Contact law": {"Law": "IQS"},
        "Compaction": {"Number of discs": "60", "Mean diameter": "1.2e-6", "Diameter spread": "0.2",
                       "Length": "1.2e-5", "Pressure": "1e8", "Pressure ramp steps": "50",
                       "Upper body thickness": "1.5e-4", "Density": "7800"},
        "Output": {"Field interval": "50", "Statistics interval": "1"},
    }

    def initial_kinetic_energy(self):
        return 0.0

    def snapshot_times(self):
        return [k * 50 * 2e-9 for k in range(5)]

    def test_steps_and_parameters(self):
        s = self.summary
        self.assertEqual(s["steps"], 200)
        self.assertEqual(s["steps_planned"], 200)
        self.assertEqual(s["time_step"], 2e-9)
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(float(f["parameters"].attrs["Simulation/Time step"]), 2e-9)
            self.assertEqual(f.attrs["time_step"], 2e-9)
            self.assertEqual(int(f["parameters"].attrs["Compaction/Number of discs"]), 60)

    def free_disc_mask(self, v):
        body = v["point_data"]["body"].ravel()
        return (body != 0) & (body != self.summary["n_bodies"] - 1)

    def test_disc_values(self):
        pvd = read_pvd(os.path.join(self.fields, "discs.pvd"))
        first = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[0][1]))
        self.assertEqual(first["n_points"], self.summary["n_discs"])
        free = self.free_disc_mask(first)
        self.assertEqual(int(free.sum()), self.N)
        self.assertEqual(self.summary["results"]["n_free_discs"], self.N)
        self.assertEqual(self.summary["n_bodies"], self.N + 2)
        r = first["point_data"]["radius"].ravel()
        lo, hi = self.D * (1 - self.S) / 2, self.D * (1 + self.S) / 2
        self.assertTrue(np.all(r[free] >= lo * (1 - F32)) and np.all(r[free] <= hi * (1 + F32)), (r.min(), r.max()))
        np.testing.assert_array_equal(first["point_data"]["velocity"], 0, "at rest at t = 0")
        x = first["points"][:, 0]
        self.assertTrue(np.all((x >= 0) & (x <= self.L * (1 + F32))), "x wrapped into [0, L)")
        self.assertAlmostEqual(self.summary["max_overlap_over_min_radius"],
                               self.summary["max_overlap"] / r.min(), delta=1e-6 * self.summary["max_overlap_over_min_radius"])

        # The last snapshot holds the state after the last step.
        last = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[-1][1]))
        body = last["point_data"]["body"].ravel()
        upper = body == self.summary["n_bodies"] - 1
        np.testing.assert_allclose(last["points"][upper, 1], self.stats["upper_wall_y"][-1], rtol=1e-6)
        np.testing.assert_allclose(last["point_data"]["velocity"][upper, 1], self.stats["upper_wall_vy"][-1], rtol=1e-6)
        np.testing.assert_array_equal(last["point_data"]["velocity"][body == 0], 0, "lower wall fixed")
        # Kinetic energy of the last row from the snapshot: grains (discs) plus the upper wall.
        free = self.free_disc_mask(last)
        rr = last["point_data"]["radius"].ravel()[free].astype(float)
        v = last["point_data"]["velocity"][free].astype(float)
        w = last["point_data"]["spin"].ravel()[free].astype(float)
        m = self.RHO * math.pi * rr ** 2
        ke = np.sum(0.5 * m * (v ** 2).sum(axis=1) + 0.5 * (0.5 * m * rr ** 2) * w ** 2)
        m_upper = self.RHO * self.THICK * self.L
        ke += 0.5 * m_upper * self.stats["upper_wall_vy"][-1] ** 2
        self.assertAlmostEqual(ke / self.stats["kinetic_energy"][-1], 1, delta=1e-5)
        # power_free covers the grains only: its work is their kinetic energy.
        grains = self.stats["kinetic_energy"][-1] - 0.5 * m_upper * self.stats["upper_wall_vy"][-1] ** 2
        work = np.sum(self.summary["time_step"] * self.stats["power_free"])
        self.assertAlmostEqual(work / grains, 1, delta=1e-9)

    def test_compaction_columns(self):
        st = self.stats
        target = self.P * self.L
        ramp = np.minimum(1.0, st["step"] / self.RAMP) * target
        np.testing.assert_allclose(st["applied_force"], ramp, rtol=1e-12)
        self.assertTrue(np.all(st["lower_wall_normal_force"] >= 0), "grains push the lower wall down")
        self.assertGreater(st["lower_wall_normal_force"].max(), 0)
        self.assertTrue(np.all((st["solid_fraction"] > 0) & (st["solid_fraction"] < 1)))
        self.assertLess(st["upper_wall_vy"][0], 0, "the upper wall starts moving down")
        self.assertLess(st["upper_wall_y"][-1], st["upper_wall_y"][0])
        # External power: the fixed lower wall does no work; the rest is the load on the upper wall.
        np.testing.assert_array_equal(st["power_lower_wall"], 0)
        np.testing.assert_allclose(st["power_lower_wall"] + st["power_upper_wall"], st["power_external"],
                                   rtol=1e-12, atol=0)
        # The load (downwards) times the mean velocity over the step (rows at every step, at rest at t = 0).
        vy_begin = np.concatenate([[0.0], st["upper_wall_vy"][:-1]])
        v_mid = 0.5 * (vy_begin + st["upper_wall_vy"])
        np.testing.assert_allclose(st["power_upper_wall"], -st["applied_force"] * v_mid,
                                   rtol=1e-9, atol=1e-12 * np.abs(st["power_upper_wall"]).max())

        # Scene results recomputed from the statistics (last fifth of the rows).
        r = self.summary["results"]
        n = len(st["step"])
        tail = slice(n - max(1, n // 5), n)
        self.assertEqual(r["target_normal_force"], target)
        self.assertAlmostEqual(r["mean_lower_wall_normal_force"] / st["lower_wall_normal_force"][tail].mean(), 1, places=12)
        self.assertAlmostEqual(r["normal_force_ratio"] * st["applied_force"][tail].sum()
                               / st["lower_wall_normal_force"][tail].sum(), 1, places=12)
        self.assertAlmostEqual(r["mean_solid_fraction"], st["solid_fraction"][tail].mean(), places=12)
        self.assertEqual(r["upper_wall_y"], st["upper_wall_y"][-1])

        # The solid fraction: grain area over the area between the wall centre lines.
        pvd = read_pvd(os.path.join(self.fields, "discs.pvd"))
        last = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[-1][1]))
        rr = last["point_data"]["radius"].ravel()[self.free_disc_mask(last)].astype(float)
        body = last["point_data"]["body"].ravel()
        y_lower = last["points"][body == 0, 1].astype(float).mean()
        phi = np.sum(math.pi * rr ** 2) / ((st["upper_wall_y"][-1] - y_lower) * self.L)
        self.assertAlmostEqual(phi / st["solid_fraction"][-1], 1, delta=1e-5)


class SparseStatistics(TempDirTestCase):
    """Statistics interval > 1: rows every N steps, and always the last step."""

    def test_rows(self):
        sections = dict(Compaction.SECTIONS)
        sections["Output"] = {"Statistics interval": "7", "Field interval": "0"}
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        _, st = read_csv(os.path.join(self.tmp, "out", "statistics.csv"))
        np.testing.assert_array_equal(st["step"], list(range(7, 200, 7)) + [200])
        s = read_json(os.path.join(self.tmp, "out", "summary.json"))
        self.assertEqual(s["n_field_snapshots"], 2, "Field interval 0: the first and the last")
        times = [t for t, _ in read_pvd(os.path.join(self.tmp, "out", "fields", "discs.pvd"))]
        np.testing.assert_allclose(times, [0, s["simulated_time"]], rtol=1e-10)
        with h5py.File(os.path.join(self.tmp, "out", "results.h5"), "r") as f:
            self.assertEqual(f["statistics"].attrs["n_rows"], len(st["step"]))
            np.testing.assert_array_equal(f["statistics/step"][()], st["step"])


class FailedRun(TempDirTestCase):
    """A run that cannot go on: exit 1, status failed, the reason in summary and log."""

    def test_failed(self):
        sections = dict(Compaction.SECTIONS)
        # A detection distance longer than half the period: the contact search refuses.
        sections["Contact law"] = {"Law": "IQS", "Detection distance": "1e-5"}
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        out = os.path.join(self.tmp, "out")
        self.assertEqual(r.returncode, 1, r.stderr)
        s = read_json(os.path.join(out, "summary.json"))
        self.assertEqual(s["status"], "failed")
        self.assertIn("period along x", s["error"])
        self.assertEqual(s["steps"], 0)
        with open(os.path.join(out, "log.txt")) as f:
            log = f.read()
        self.assertIn("status failed", log)
        self.assertIn("error: " + s["error"], log)
        with h5py.File(os.path.join(out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            self.assertEqual(f["statistics"].attrs["n_rows"], 0)
        self.assertEqual(tmp_files(out), [])
        self.assertEqual(s["n_field_snapshots"], 2)


if __name__ == "__main__":
    tribo_cli.main()
