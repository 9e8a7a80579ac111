"""The output directory of `tribo run` (docs/outputs.md), checked by value:
statistics.csv, results.h5, summary.json, the VTU snapshots and their .pvd
indices, profiles.csv and the PNG plots, for a small ELAS collision, a small
compaction-only shear run and a small sliding shear run; a failing run.

The physics of steady shear (equilibrium, power balance) is not asserted
here: only what each output means, as docs/outputs.md defines it.

Usage: /usr/bin/python3 test_outputs.py /path/to/tribo
"""

import csv
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
from tribo_cli import (COMMON_COLUMNS, PLOTS, PROFILE_COLUMNS, PROFILE_QUANTITIES, SCENE_COLUMNS,  # noqa: E402
                       TempDirTestCase, decode_vtu, read_csv, read_json, read_png, read_pvd,
                       read_vtu_with_vtk, run, tmp_files, write_prm)

FILES = ["fields", "log.txt", "original.prm", "parameters.prm", "results.h5",
         "statistics.csv", "summary.json"]

# Float32 in the VTU files: relative precision of the stored values.
F32 = 2e-7


class RunOnce:
    """Mixin: run the case SECTIONS once for the whole class, in a fresh temporary
    directory, and check what every scene shares."""

    SECTIONS = None
    #: Files of the output directory besides FILES.
    EXTRA_FILES = []

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
        self.assertEqual(sorted(os.listdir(self.out)), sorted(FILES + self.EXTRA_FILES))
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
        self.assertEqual(s["solver_iterations_total"], int(st["solver_iterations"].sum()))
        self.assertEqual(s["solver_iterations_max"], int(st["solver_iterations"].max()))
        self.assertAlmostEqual(s["solver_iterations_mean"], st["solver_iterations"].mean(), places=9)
        self.assertEqual(s["solver_non_converged_steps"], int((st["solver_converged"] == 0).sum()))
        self.assertEqual(s["solver_residual_max"], st["solver_residual"].max())
        self.assertEqual(s["max_overlap"], st["max_overlap"].max())
        self.assertTrue(set(np.unique(st["solver_converged"])) <= {0.0, 1.0})
        self.assertTrue(np.all(st["n_active_contacts"] <= st["n_contacts"]))
        self.assertTrue(np.all(st["max_overlap"] >= 0))
        self.assertGreater(s["wall_time"], 0)
        self.assertEqual(s["n_field_snapshots"], len(read_pvd(os.path.join(self.fields, "discs.pvd"))))

    def imposed_kinetic_energy(self):
        """Kinetic energy of the bodies whose imposed velocity changes during the run
        (none by default), per row: it changes without power."""
        return 0.0

    def kinetic_energy_removed(self):
        """Kinetic energy taken out between steps (a velocity cap), summed up to each row."""
        return 0.0

    def test_energy_balance(self):
        """Sum of h (power_contacts + power_external) is the change of kinetic energy
        (exact for the Moreau-Jean update, rows at every step), bodies whose imposed
        velocity jumps left out."""
        st, h = self.stats, self.summary["time_step"]
        ke0 = self.initial_kinetic_energy()
        ke = st["kinetic_energy"] - self.imposed_kinetic_energy() + self.kinetic_energy_removed()
        work = np.cumsum(h * (st["power_contacts"] + st["power_external"]))
        scale = max(np.abs(ke).max(), ke0)
        np.testing.assert_allclose(work, ke - ke0, rtol=0, atol=1e-9 * scale)

    def tables(self):
        """The scene's extra tables: {NAME: (header, columns)} of every NAME.csv."""
        return {f[:-4]: read_csv(os.path.join(self.out, f)) for f in os.listdir(self.out)
                if f.endswith(".csv") and f not in ("statistics.csv", "sample_final.csv")}

    def test_results_h5(self):
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["complete"], 1)
            self.assertEqual(f.attrs["steps"], self.summary["steps"])
            self.assertEqual(f.attrs["time_step"], self.summary["time_step"])
            self.assertEqual(f.attrs["simulated_time"], self.summary["simulated_time"])
            self.assertEqual(f.attrs["wall_time"], self.summary["wall_time"])
            tables = self.tables()
            self.assertEqual(sorted(f.keys()), sorted(["statistics", "parameters"] + list(tables)))
            for name, (header, columns) in tables.items():
                g = f[name]
                n_rows = len(columns[header[0]])
                self.assertEqual(g.attrs["n_rows"], n_rows, name)
                # No dataset for a table without rows (as for /statistics).
                self.assertEqual(sorted(g.keys()), sorted(header) if n_rows else [], name)
                for column in (header if n_rows else []):
                    np.testing.assert_array_equal(g[column][()], columns[column],
                                                  err_msg="%s/%s" % (name, column))
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
        self.assertFalse([l for l in lines if l.startswith("warning")], "no warnings")

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
        """docs/outputs.md names every file, column, summary key, table column, HDF5
        group and VTU array (in backquotes)."""
        with open(tribo_cli.OUTPUTS_MD) as f:
            doc = f.read()
        names = list(self.header) + list(self.summary) + list(self.summary["results"])
        names += ["radius", "velocity", "spin", "body", "normal_force", "tangential_force", "gap",
                  "complete", "n_rows", "statistics", "parameters"]
        for name, (header, _) in self.tables().items():
            names += [name] + header
        names += [f for f in os.listdir(self.out) if f != "fields"]
        missing = [n for n in names if "`%s`" % n not in doc]
        self.assertEqual(missing, [], "undocumented in docs/outputs.md")
        self.assertIn("`fields/", doc)


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


# ---------------------------------------------------------------------------
# The shear scene.

#: summary.json "results" keys of a shear run, in this order (docs/outputs.md).
COMPACTION_RESULTS = ["sliding", "averaging_start", "normal_force_mean", "normal_force_stderr",
                      "normal_force_target", "third_body_thickness", "third_body_thickness_stderr",
                      "solid_fraction_mean", "solid_fraction_stderr", "face_shift_mean", "face_shift_stderr",
                      "face_shift_max", "face_shift_in_half_discs", "cohesion_number"]
SLIDING_RESULTS = ["sliding", "steady_state_reached", "steady_state_start", "upper_body_vy_at_shear_start",
                   "upper_body_vy_before_shear",
                   "averaging_start",
                   "normal_force_mean", "normal_force_stderr", "normal_force_target",
                   "third_body_thickness", "third_body_thickness_stderr", "solid_fraction_mean",
                   "solid_fraction_stderr", "face_shift_mean", "face_shift_stderr", "face_shift_max",
                   "face_shift_in_half_discs", "cohesion_number", "mu_mean", "mu_std", "mu_stderr",
                   "power_lower_wall_mean", "power_lower_wall_stderr", "power_upper_wall_mean",
                   "power_upper_wall_stderr", "power_dissipated_mean", "power_dissipated_stderr",
                   "power_third_body_mean", "power_third_body_stderr", "power_balance_ratio", "power_balance_ratio_stderr",
                   "energy_rate_mean", "power_balance_closure", "inertial_number",
                   "profile_samples_in_steady_state", "profile_steps_per_sample", "sigma_xx_mean", "sigma_xx_stderr",
                   "sigma_yy_mean", "sigma_yy_stderr", "sigma_xy_mean", "sigma_xy_stderr"]


def shear_sections(n, end_time, shear_start, ramp_time, plots, **extra):
    """A small shear case: N discs, L = 1.2e-5 m, walls of L/d discs, h = 2e-9 s.
    @p extra: {"Subsection": {entry: value}} merged in."""
    sections = {
        "Simulation": {"Scene": "shear", "Time step": "2e-9", "End time": end_time},
        "Contact law": {"Law": "IQS"},
        # Output checks, not accuracy: 1e-3 keeps these tiny packings clear of the
        # sweep cap (docs/laws.md, "Convergence norms").
        "Solver": {"Tolerance": "1e-3"},
        "Shear cell": {"Number of discs": n, "Mean diameter": "1.2e-6", "Diameter spread": "0.2",
                       "Length": "1.2e-5", "Wall discs": "0", "Pressure": "1e8",
                       "Pressure ramp time": ramp_time, "Shear start": shear_start,
                       "Upper body thickness": "1.5e-4", "Density": "7800"},
        "Output": {"Statistics interval": "1", "Plots": plots},
    }
    for section, entries in extra.items():
        sections.setdefault(section, {}).update(entries)
    return sections


def steady_state(time, series, absolute, t0, t1, tolerance=0.1):
    """The steady-state rule of docs/outputs.md (app/steady_state.h), from the rows."""
    for k in range(1, 6):
        s = t0 + k * (t1 - t0) / 10
        mid = 0.5 * (s + t1)
        ok = True
        for v, a_min in zip(series, absolute):
            first = (time >= s) & (time < mid)
            second = (time >= mid) & (time < t1 + 1e-30 + 1e-12 * abs(t1))
            if not first.any() or not second.any():
                ok = False
                break
            a, b = v[first].mean(), v[second].mean()
            if not abs(a - b) <= max(tolerance * max(abs(a), abs(b)), a_min):
                ok = False
                break
        if ok:
            return True, s
    return False, 0.5 * (t0 + t1)


class ShearRun(RunOnce):
    """Checks shared by the compaction-only and the sliding shear runs (60 or 100
    discs, IQS without cohesion, walls of L/d = 10 discs, rows at every step)."""

    D, S, L, RHO, P, THICK, H = 1.2e-6, 0.2, 1.2e-5, 7800.0, 1e8, 1.5e-4, 2e-9
    N = RAMP_TIME = SHEAR_START = END_TIME = FIELD_INTERVAL = None

    def initial_kinetic_energy(self):
        return 0.0

    def snapshot_times(self):
        steps = int(round(self.END_TIME / self.H))
        return [k * self.FIELD_INTERVAL * self.H for k in range(steps // self.FIELD_INTERVAL + 1)]

    @classmethod
    def discs(cls):
        """The first snapshot: {"lower", "upper", "grains"} radius arrays (float64 of the
        stored float32) and the snapshot itself."""
        if not hasattr(cls, "_discs"):
            pvd = read_pvd(os.path.join(cls.fields, "discs.pvd"))
            first = decode_vtu(os.path.join(cls.fields, pvd[0][1]))
            body = first["point_data"]["body"].ravel()
            r = first["point_data"]["radius"].ravel().astype(float)
            upper = cls.summary["n_bodies"] - 1
            cls._discs = {"lower": r[body == 0], "upper": r[body == upper],
                          "grains": r[(body != 0) & (body != upper)], "snapshot": first}
        return cls._discs

    @classmethod
    def parameters(cls):
        """Every parameter as used, {"Subsection/Entry": text}, from results.h5."""
        if not hasattr(cls, "_parameters"):
            with h5py.File(os.path.join(cls.out, "results.h5"), "r") as f:
                cls._parameters = {k: str(v) for k, v in f["parameters"].attrs.items()}
        return cls._parameters

    def upper_wall_vy_begin(self):
        """The upper wall's y velocity at the start of each step (rows at every step):
        the previous row's, capped at Shear cell/Compaction speed limit (if > 0) for
        the steps starting before Shear start."""
        st, h = self.stats, self.summary["time_step"]
        v = np.concatenate([[0.0], st["upper_wall_vy"][:-1]])
        limit = float(self.parameters().get("Shear cell/Compaction speed limit", "0"))
        if limit > 0:
            compacting = (st["step"] - 1) * h < self.SHEAR_START
            v[compacting] = np.clip(v[compacting], -limit, limit)
        return v

    def kinetic_energy_removed(self):
        """The speed cap takes m (v_before^2 - v_capped^2)/2 from the upper wall."""
        st = self.stats
        v_before = np.concatenate([[0.0], st["upper_wall_vy"][:-1]])
        m = self.RHO * self.THICK * self.L
        return np.cumsum(0.5 * m * (v_before ** 2 - self.upper_wall_vy_begin() ** 2))

    def mean_wall_diameter(self):
        d = self.discs()
        return np.concatenate([2 * d["lower"], 2 * d["upper"]]).mean()

    def sliding_rows(self):
        """Rows of the steps during which the lower wall slides: the step starting at
        t = (step - 1) h >= Shear start."""
        return (self.stats["step"] - 1) * self.summary["time_step"] >= self.SHEAR_START

    def test_steps_and_parameters(self):
        s = self.summary
        steps = int(round(self.END_TIME / self.H))
        self.assertEqual(s["steps"], steps)
        self.assertEqual(s["steps_planned"], steps)
        self.assertEqual(s["time_step"], self.H)
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(float(f["parameters"].attrs["Simulation/Time step"]), self.H)
            self.assertEqual(f.attrs["time_step"], self.H)
            self.assertEqual(int(f["parameters"].attrs["Shear cell/Number of discs"]), self.N)
            self.assertEqual(f["parameters"].attrs["Output/Plots"], self.SECTIONS["Output"]["Plots"])

    def test_sample_final(self):
        """sample_final.csv: every disc once, grains inside the period, the radii those of
        the first snapshot, each wall's rows moving together."""
        with open(os.path.join(self.out, "sample_final.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(list(rows[0]), ["x", "y", "r", "body", "vx", "vy", "spin"])
        self.assertEqual(len(rows), self.summary["n_discs"])
        by_body = {b: [r for r in rows if r["body"] == b] for b in ("grain", "lower_wall", "upper_wall")}
        self.assertEqual(len(by_body["grain"]), self.N)
        self.assertEqual(len(by_body["lower_wall"]), 10)
        self.assertEqual(len(by_body["upper_wall"]), 10)
        for r in by_body["grain"]:
            self.assertTrue(0 <= float(r["x"]) < self.L, r)
        d = self.discs()
        np.testing.assert_allclose(sorted(float(r["r"]) for r in by_body["grain"]), sorted(d["grains"]), rtol=1e-6)
        for wall in ("lower_wall", "upper_wall"):
            self.assertEqual(len({(r["vx"], r["vy"], r["spin"]) for r in by_body[wall]}), 1, wall)
        # The upper wall's rows sit at its final height (statistics.csv, last row).
        upper_y = np.mean([float(r["y"]) for r in by_body["upper_wall"]])
        self.assertAlmostEqual(upper_y / self.stats["upper_wall_y"][-1], 1, delta=1e-9)

    def test_results_keys(self):
        r = self.summary["results"]
        self.assertEqual(list(r), SLIDING_RESULTS if self.sliding else COMPACTION_RESULTS)
        self.assertIs(r["sliding"], self.sliding)

    def test_disc_values(self):
        d = self.discs()
        first = read_vtu_with_vtk(self, os.path.join(self.fields, read_pvd(os.path.join(self.fields, "discs.pvd"))[0][1]))
        self.assertEqual(first["n_points"], self.summary["n_discs"])
        # Wall discs 0: round(L/d) = 10 discs per wall.
        self.assertEqual(len(d["lower"]), 10)
        self.assertEqual(len(d["upper"]), 10)
        self.assertEqual(len(d["grains"]), self.N)
        self.assertEqual(self.summary["n_bodies"], self.N + 2)
        self.assertEqual(self.summary["n_discs"], self.N + 20)
        r = first["point_data"]["radius"].ravel()
        lo, hi = self.D * (1 - self.S) / 2, self.D * (1 + self.S) / 2
        self.assertTrue(np.all(r >= lo * (1 - F32)) and np.all(r <= hi * (1 + F32)), (r.min(), r.max()))
        np.testing.assert_array_equal(first["point_data"]["velocity"], 0, "at rest at t = 0")
        x = first["points"][:, 0]
        self.assertTrue(np.all((x >= 0) & (x <= self.L * (1 + F32))), "x wrapped into [0, L)")
        body = first["point_data"]["body"].ravel()
        np.testing.assert_array_equal(first["points"][body == 0, 1], 0, "lower wall centre line at y = 0")
        self.assertAlmostEqual(self.summary["max_overlap_over_min_radius"],
                               self.summary["max_overlap"] / r.min(), delta=1e-6 * self.summary["max_overlap_over_min_radius"])

        # The last snapshot holds the state after the last step.
        pvd = read_pvd(os.path.join(self.fields, "discs.pvd"))
        last = read_vtu_with_vtk(self, os.path.join(self.fields, pvd[-1][1]))
        body = last["point_data"]["body"].ravel()
        upper = body == self.summary["n_bodies"] - 1
        np.testing.assert_allclose(last["points"][upper, 1], self.stats["upper_wall_y"][-1], rtol=1e-6)
        np.testing.assert_allclose(last["point_data"]["velocity"][upper, 1], self.stats["upper_wall_vy"][-1], rtol=1e-6)
        np.testing.assert_array_equal(last["point_data"]["velocity"][upper, 0], 0, "upper wall: no x motion")
        np.testing.assert_array_equal(last["point_data"]["spin"][upper], 0, "upper wall: no rotation")
        v_lower = self.SECTIONS["Shear cell"].get("Sliding velocity", "5") if self.sliding else 0
        np.testing.assert_allclose(last["point_data"]["velocity"][body == 0],
                                   [[float(v_lower), 0, 0]] * 10, rtol=F32, atol=0)
        np.testing.assert_allclose(last["points"][body == 0, 1], 0, atol=1e-20)
        # The kinetic energy of the grains from the snapshot.
        free = (body != 0) & ~upper
        rr = last["point_data"]["radius"].ravel()[free].astype(float)
        v = last["point_data"]["velocity"][free].astype(float)
        w = last["point_data"]["spin"].ravel()[free].astype(float)
        m = self.RHO * math.pi * rr ** 2
        ke = np.sum(0.5 * m * (v ** 2).sum(axis=1) + 0.5 * (0.5 * m * rr ** 2) * w ** 2)
        self.assertAlmostEqual(ke / self.stats["kinetic_energy_third_body"][-1], 1, delta=1e-5)

    def test_shear_columns(self):
        """Every column by its definition, in every row."""
        st, h = self.stats, self.summary["time_step"]
        # The applied force: P L ramped linearly over the ramp time.
        ramp = np.minimum(1.0, st["time"] / self.RAMP_TIME) * self.P * self.L
        np.testing.assert_allclose(st["normal_force"], ramp, rtol=1e-12)
        self.assertTrue(np.all(st["lower_wall_normal_force"] >= 0), "no cohesion: the grains push the lower wall down")
        self.assertLess(st["upper_wall_vy"][0], 0, "the upper wall starts moving down")
        self.assertLess(st["upper_wall_y"][-1], st["upper_wall_y"][0])
        # The gap between the wall centre lines (the lower one at y = 0).
        np.testing.assert_array_equal(st["gap"], st["upper_wall_y"])
        # The solid fraction: grain area over (gap - mean wall diameter) L.
        area = np.sum(math.pi * self.discs()["grains"] ** 2)
        np.testing.assert_allclose(st["solid_fraction"] * (st["gap"] - self.mean_wall_diameter()) * self.L,
                                   area, rtol=2e-6)
        # Kinetic energies: the upper wall moves in y only (its mass: density x thickness x L).
        np.testing.assert_allclose(st["kinetic_energy_upper_wall"],
                                   0.5 * self.RHO * self.THICK * self.L * st["upper_wall_vy"] ** 2, rtol=1e-12)
        self.assertTrue(np.all(st["kinetic_energy_third_body"] >= 0))
        # The grains are the free bodies: the work of power_free is their kinetic energy.
        np.testing.assert_allclose(np.cumsum(h * st["power_free"]), st["kinetic_energy_third_body"],
                                   rtol=0, atol=1e-9 * st["kinetic_energy_third_body"].max())
        # Powers: the walls are the only driven bodies; the dissipation is minus the contact power.
        np.testing.assert_allclose(st["power_lower_wall"] + st["power_upper_wall"], st["power_external"],
                                   rtol=1e-12, atol=1e-14 * np.abs(st["power_external"]).max())
        np.testing.assert_array_equal(st["power_dissipated"], -st["power_contacts"])
        # The upper wall: the downward load times the mean y velocity over the step.
        v_mid = 0.5 * (self.upper_wall_vy_begin() + st["upper_wall_vy"])
        np.testing.assert_allclose(st["power_upper_wall"], -st["normal_force"] * v_mid,
                                   rtol=1e-9, atol=1e-12 * np.abs(st["power_upper_wall"]).max())
        # The lower wall does no work while it is fixed.
        sliding = self.sliding_rows()
        np.testing.assert_array_equal(st["power_lower_wall"][~sliding], 0)
        np.testing.assert_array_equal(st["kinetic_energy"][~sliding],
                                      st["kinetic_energy_third_body"][~sliding] + st["kinetic_energy_upper_wall"][~sliding])
        self.assertTrue(np.all(np.isfinite(st["mu"])))

    def test_common_results(self):
        """The results of every shear run, recomputed from the statistics."""
        r, st = self.summary["results"], self.stats
        window = st["time"] >= r["averaging_start"]
        self.assertTrue(window.any())
        self.assertEqual(r["normal_force_target"], self.P * self.L)
        np.testing.assert_allclose(r["normal_force_mean"], st["lower_wall_normal_force"][window].mean(), rtol=1e-12)
        np.testing.assert_allclose(r["solid_fraction_mean"], st["solid_fraction"][window].mean(), rtol=1e-12)
        np.testing.assert_allclose(r["third_body_thickness"], st["gap"][window].mean() - self.mean_wall_diameter(),
                                   rtol=1e-6)
        self.assertEqual(r["cohesion_number"], 0, "no cohesion")


class Compaction(ShearRun, unittest.TestCase):
    """A compaction-only shear run: 60 discs pressed for 200 steps, Shear start > End time."""

    N, RAMP_TIME, SHEAR_START, END_TIME, FIELD_INTERVAL = 60, 1e-7, 1e-6, 4e-7, 50
    sliding = False
    EXTRA_FILES = ["profiles.csv", "sample_final.csv"]
    SECTIONS = shear_sections("60", "4e-7", "1e-6", "1e-7", "false",
                              Output={"Field interval": "50"})

    def test_compaction_results(self):
        r, st = self.summary["results"], self.stats
        # Averaging over the last fifth of the time covered by the rows.
        t0, t1 = st["time"][0], st["time"][-1]
        self.assertEqual(r["averaging_start"], t0 + 0.8 * (t1 - t0))
        np.testing.assert_array_equal(st["power_lower_wall"], 0)

    def test_default_method_and_the_nlgs_entry_it_ignores(self):
        """The default method is APGS; the case's Solver/Tolerance, an NLGS entry, is named
        in the log as having no effect on this case."""
        self.assertEqual(self.summary["solver_method"], "apgs")
        with open(os.path.join(self.out, "log.txt")) as f:
            log = f.read()
        self.assertRegex(log, r"Solver/Method = apgs stops at Solver/Residual target = 0\.001; the NLGS entries "
                         r"Solver/Tolerance \(case\.prm:\d+\) have no effect on this case "
                         r"\(they act with Method = nlgs\)")

    def test_no_profiles(self):
        """No shearing, no profile sample: profiles.csv has its header only, the HDF5
        group "profiles" no datasets; no plots (Plots = false)."""
        header, columns = read_csv(os.path.join(self.out, "profiles.csv"))
        self.assertEqual(header, PROFILE_COLUMNS)
        self.assertEqual(len(columns["layer"]), 0)
        with h5py.File(os.path.join(self.out, "results.h5"), "r") as f:
            self.assertEqual(f["profiles"].attrs["n_rows"], 0)
            self.assertEqual(list(f["profiles"].keys()), [])


class Sliding(ShearRun, unittest.TestCase):
    """A sliding shear run: 100 discs compacted for 200 steps, then sheared at V = 5 m/s
    for 800 steps with 50 profile samples; plots on."""

    N, RAMP_TIME, SHEAR_START, END_TIME, FIELD_INTERVAL = 100, 2e-7, 4e-7, 2e-6, 500
    V, SAMPLES = 5.0, 50
    sliding = True
    EXTRA_FILES = ["profiles.csv", "sample_final.csv"] + PLOTS
    SECTIONS = shear_sections("100", "2e-6", "4e-7", "2e-7", "true",
                              **{"Shear cell": {"Sliding velocity": "5", "Profile samples": "50"},
                                 "Output": {"Field interval": "500"}})

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.profile_header, cls.profiles = read_csv(os.path.join(cls.out, "profiles.csv"))

    def imposed_kinetic_energy(self):
        """The lower wall's, which jumps to m V^2/2 at Shear start."""
        st = self.stats
        return st["kinetic_energy"] - st["kinetic_energy_third_body"] - st["kinetic_energy_upper_wall"]

    def block_steps(self):
        """Steps per profile sample: the shearing steps over Profile samples, rounded up."""
        first, n = round(self.SHEAR_START / self.H), round(self.END_TIME / self.H)
        return -(-(n - first) // self.SAMPLES)

    def sample_times(self):
        """The times of the profile samples: blocks of block_steps() consecutive steps
        from Shear start on, each at the beginning of its first step."""
        first, n, b = round(self.SHEAR_START / self.H), round(self.END_TIME / self.H), self.block_steps()
        return np.array([(first + k * b) * self.H for k in range(-(-(n - first) // b))])

    def test_lower_wall(self):
        sliding = self.sliding_rows()
        self.assertEqual(int(sliding.sum()), 800)
        m_lower = self.RHO * math.pi * np.sum(self.discs()["lower"] ** 2)
        ke_lower = self.imposed_kinetic_energy()
        np.testing.assert_allclose(ke_lower[sliding], 0.5 * m_lower * self.V ** 2, rtol=1e-6)
        np.testing.assert_allclose(ke_lower[~sliding], 0, atol=1e-12 * ke_lower.max())

    def test_upper_body_speed_at_shear_start(self):
        """upper_body_vy_at_shear_start is upper_wall_vy after the last step before Shear
        start, upper_body_vy_before_shear its mean over the statistics rows of the last
        microsecond before it; above 1 % of V the log's averaging line says, from the mean,
        that the body had not landed."""
        r, st = self.summary["results"], self.stats
        last_before = st["step"] == round(self.SHEAR_START / self.H)
        vy = st["upper_wall_vy"][last_before][0]
        self.assertEqual(r["upper_body_vy_at_shear_start"], vy)
        window = (st["time"] >= self.SHEAR_START - 1e-6) & (st["time"] < self.SHEAR_START)
        self.assertGreater(int(window.sum()), 1)
        mean = st["upper_wall_vy"][window].mean()
        self.assertAlmostEqual(r["upper_body_vy_before_shear"], mean, delta=1e-12 * max(1.0, abs(mean)))
        with open(os.path.join(self.out, "log.txt")) as f:
            log = f.read()
        note = ("Over the last microsecond before Shear start the upper body was still moving at %g m/s on "
                "average (more than 1 %% of the sliding velocity): the layer had not finished compacting"
                % r["upper_body_vy_before_shear"])
        if abs(mean) > 0.01 * self.V:
            self.assertIn(note, log)
        else:
            self.assertNotIn("the upper body was still moving", log)
        print(f"upper body at Shear start: {vy:.4g} m/s, over the microsecond before it {mean:.4g} m/s")

    def test_mu(self):
        """mu = -F_x / normal_force, F_x the x contact force on the lower wall, whose
        power is -F_x V: power_lower_wall = mu normal_force V (to round-off)."""
        st = self.stats
        sliding = self.sliding_rows()
        expected = st["mu"] * st["normal_force"] * self.V
        np.testing.assert_allclose(st["power_lower_wall"][sliding], expected[sliding], rtol=1e-12,
                                   atol=1e-12 * np.abs(expected).max())
        self.assertGreater(np.abs(st["power_lower_wall"][sliding]).max(), 0)

    def test_steady_state_and_means(self):
        r, st = self.summary["results"], self.stats
        t1 = st["time"][-1]
        reached, start = steady_state(st["time"], [st["mu"], st["kinetic_energy"]], [0.01, 0.0],
                                      self.SHEAR_START, t1)
        self.assertIs(r["steady_state_reached"], reached)
        self.assertEqual(r["steady_state_start"], start)
        self.assertEqual(r["averaging_start"], r["steady_state_start"])
        w = st["time"] >= r["averaging_start"]
        for key, column in (("mu_mean", "mu"), ("power_lower_wall_mean", "power_lower_wall"),
                            ("power_upper_wall_mean", "power_upper_wall"),
                            ("power_dissipated_mean", "power_dissipated"),
                            ("power_third_body_mean", "power_free")):
            np.testing.assert_allclose(r[key], st[column][w].mean(), rtol=1e-12, err_msg=key)
        np.testing.assert_allclose(r["mu_std"], st["mu"][w].std(), rtol=1e-9)
        # Standard errors by batch means: B = 10 contiguous batches of the window's rows.
        def batches(v):
            n = len(v)
            return np.array([v[b * n // 10:(b + 1) * n // 10].mean() for b in range(10)])

        def stderr(m):
            return m.std(ddof=1) / math.sqrt(len(m))

        for key, column in (("mu_stderr", "mu"), ("normal_force_stderr", "lower_wall_normal_force"),
                            ("solid_fraction_stderr", "solid_fraction"), ("third_body_thickness_stderr", "gap"),
                            ("power_lower_wall_stderr", "power_lower_wall"),
                            ("power_upper_wall_stderr", "power_upper_wall"),
                            ("power_dissipated_stderr", "power_dissipated"), ("power_third_body_stderr", "power_free")):
            np.testing.assert_allclose(r[key], stderr(batches(st[column][w])), rtol=1e-9, err_msg=key)
        np.testing.assert_allclose(r["power_balance_ratio_stderr"],
                                   stderr(batches(st["power_dissipated"][w]) / batches(st["power_lower_wall"][w])),
                                   rtol=1e-9)
        self.assertGreater(r["mu_stderr"], 0)
        np.testing.assert_allclose(r["power_balance_ratio"], r["power_dissipated_mean"] / r["power_lower_wall_mean"],
                                   rtol=1e-12)
        # The whole balance (rigid upper wall: the energy is the grains' kinetic energy).
        tw, kw = st["time"][w], st["kinetic_energy"][w]
        np.testing.assert_allclose(r["energy_rate_mean"], (kw[-1] - kw[0]) / (tw[-1] - tw[0]), rtol=1e-9)
        # Over the rows after the window's first: their steps are those between the two energies.
        after = {name: st[name][w][1:].mean() for name in ("power_dissipated", "power_damping_upper_body",
                                                          "power_lower_wall", "power_upper_wall")}
        np.testing.assert_allclose(r["power_balance_closure"],
                                   (after["power_dissipated"] + after["power_damping_upper_body"] +
                                    r["energy_rate_mean"]) / (after["power_lower_wall"] + after["power_upper_wall"]),
                                   rtol=1e-9)
        # With one row per step and a rigid upper wall the books close to round-off.
        self.assertAlmostEqual(r["power_balance_closure"], 1, delta=1e-9)
        d_grains = 2 * self.discs()["grains"].mean()
        np.testing.assert_allclose(r["inertial_number"],
                                   self.V / r["third_body_thickness"] * d_grains * math.sqrt(self.RHO / self.P),
                                   rtol=1e-6)

    def test_profiles_table(self):
        """profiles.csv: the documented columns; the samples, layers and stresses by definition."""
        self.assertEqual(self.profile_header, PROFILE_COLUMNS)
        p, r = self.profiles, self.summary["results"]
        n = len(p["layer"])
        np.testing.assert_array_equal(p["layer"], np.arange(n))
        # The samples averaged: those at or after the start of the steady state.
        times = self.sample_times()
        self.assertEqual(len(times), self.SAMPLES)
        steady = times >= r["steady_state_start"]
        self.assertEqual(r["profile_samples_in_steady_state"], int(steady.sum()))
        self.assertGreater(steady.sum(), 0)
        np.testing.assert_array_equal(p["n_samples"], steady.sum())
        # Standard errors by batch means: finite and non-negative, and the grains' velocities
        # do fluctuate from batch to batch in every layer.
        for q in PROFILE_QUANTITIES:
            self.assertTrue(np.all(np.isfinite(p[q + "_stderr"]) & (p[q + "_stderr"] >= 0)), q)
        self.assertTrue(np.all(p["vx_stderr"] > 0))
        # Every step of the steady blocks counts: the layers' dissipation adds up to the
        # mean contact dissipation over those steps (rows ending after the first block's
        # beginning), to round-off.
        self.assertEqual(r["profile_steps_per_sample"], self.block_steps())
        in_blocks = self.stats["time"] > times[steady][0] + 0.5 * self.H
        np.testing.assert_allclose(p["power_dissipated"].sum(), self.stats["power_dissipated"][in_blocks].mean(),
                                   rtol=1e-9)
        self.assertTrue(np.all(p["granular_temperature"] >= 0) and p["granular_temperature"].max() > 0)
        # Layers: fixed at the first shearing step, about one mean diameter each.
        mwd = self.mean_wall_diameter()
        gap_at = {round(t / self.H): g for t, g in zip(self.stats["time"], self.stats["gap"])}
        h_first = gap_at[round(times[0] / self.H) + 1] - mwd
        self.assertEqual(n, max(1, int(round(h_first / self.D))))
        # (The layer may still compact after the first sample: only roughly the final thickness.)
        thickness = r["third_body_thickness"] / self.D
        self.assertTrue(0.5 * thickness <= n <= 2 * thickness, "about the gap thickness over the mean diameter")
        # Positions: layer centres over the mean gap between the wall surfaces.
        np.testing.assert_allclose(p["y_over_h"], (p["layer"] + 0.5) / n, rtol=1e-12)
        self.assertTrue(np.all(np.diff(p["y"]) > 0) and np.all(np.diff(p["y_over_h"]) > 0))
        self.assertLess(p["y_over_h"][0], 1.0 / n)
        self.assertGreater(p["y_over_h"][-1], 1 - 1.0 / n)
        h_mean = np.mean(self.stats["gap"][in_blocks]) - mwd
        np.testing.assert_allclose(p["y"] / p["y_over_h"], h_mean, rtol=1e-6)
        # Every grain is counted in one layer.
        np.testing.assert_allclose(p["n_discs"].sum(), self.N, rtol=1e-12)
        self.assertTrue(np.all((p["solid_fraction"] > 0) & (p["solid_fraction"] < 1)))
        # Compression positive: every frictionless compressive contact adds a
        # positive semi-definite, symmetric term.
        self.assertTrue(np.all(p["sigma_xx"] >= 0) and np.all(p["sigma_yy"] >= 0))
        np.testing.assert_allclose(p["sigma_xy"], p["sigma_yx"], rtol=1e-9,
                                   atol=1e-12 * np.abs(p["sigma_yy"]).max())
        # Summary stresses: mean over the layers 2 .. n - 3.
        self.assertGreaterEqual(n, 5)
        for q in ("sigma_xx", "sigma_yy", "sigma_xy"):
            np.testing.assert_allclose(r[q + "_mean"], p[q][2:n - 2].mean(), rtol=1e-12, err_msg=q)

    def test_plots(self):
        """Output/Plots = true: mu.png, power.png and profiles.png are real images."""
        for name in PLOTS:
            image = read_png(self, os.path.join(self.out, name))
            self.assertGreater(image.shape[0], 100, name)
            self.assertGreater(image.shape[1], 100, name)
            self.assertGreater(np.ptp(image), 0, "%s is not blank" % name)


class CompactionOnlyAtEndTime(TempDirTestCase):
    """Shear start = End time is a compaction-only run (Shear cell/Shear start: "at or after
    Simulation/End time the run only compacts")."""

    def test_not_sliding(self):  # = 4.0000000000000003e-07 > 4e-07: reported, to be fixed there
        write_prm(os.path.join(self.tmp, "case.prm"), shear_sections("60", "4e-7", "4e-7", "1e-7", "false"))
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = read_json(os.path.join(self.tmp, "out", "summary.json"))
        _, st = read_csv(os.path.join(self.tmp, "out", "statistics.csv"))
        np.testing.assert_array_equal(st["power_lower_wall"], 0, "the lower wall never slides")
        self.assertEqual(list(s["results"]), COMPACTION_RESULTS)
        self.assertIs(s["results"]["sliding"], False)


class Plots(TempDirTestCase):
    """Plots of a compaction-only run: mu.png and power.png but no profiles.png; a
    new run in the same directory deletes the plots of the previous one."""

    def test_compaction_plots_and_rerun(self):
        write_prm(os.path.join(self.tmp, "case.prm"), shear_sections("60", "1e-7", "1e-6", "1e-7", "true"))
        out = os.path.join(self.tmp, "out")
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        for name in ("mu.png", "power.png"):
            image = read_png(self, os.path.join(out, name))
            self.assertGreater(min(image.shape[:2]), 100, name)
        self.assertFalse(os.path.exists(os.path.join(out, "profiles.png")), "no profiles, no profiles.png")
        # A stale profiles.png and a file of the user's; then a run without plots.
        with open(os.path.join(out, "profiles.png"), "w") as f:
            f.write("stale")
        with open(os.path.join(out, "notes.txt"), "w") as f:
            f.write("mine")
        r = run(["run", "case.prm", "--output", "out", "--quiet", "--set", "Output/Plots=false"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(os.listdir(out)), sorted(FILES + ["profiles.csv", "sample_final.csv", "notes.txt"]))

    def test_plots_of_one_row(self):  # (TypeError: len() of numpy.float64): reported, to be fixed there
        """A single statistics row (Statistics interval beyond the run) still gets its plots."""
        sections = shear_sections("60", "1e-7", "1e-6", "1e-7", "true")
        sections["Output"]["Statistics interval"] = "1000"
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "out", "log.txt")) as f:
            self.assertNotIn("warning: the plots could not be made", f.read())
        for name in ("mu.png", "power.png"):
            read_png(self, os.path.join(self.tmp, "out", name))


class CollisionNotSeparated(TempDirTestCase):
    """A collision stopped before the discs touch: energy_loss and restitution_coefficient null."""

    def test_null_results(self):
        sections = {"Simulation": {"Scene": "collision", "Time step": "1e-11", "End time": "1e-10"},
                    "Contact law": {"Law": "ELAS"},
                    "Collision": {"Initial gap": "1e-9", "Impact velocity": "2"}}
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        res = read_json(os.path.join(self.tmp, "out", "summary.json"))["results"]
        self.assertIs(res["separated"], False)
        self.assertIsNone(res["energy_loss"])
        self.assertIsNone(res["restitution_coefficient"])
        self.assertEqual(res["contact_duration"], 0)


class SparseStatistics(TempDirTestCase):
    """Statistics interval > 1: rows every N steps, and always the last step."""

    def test_rows(self):
        sections = shear_sections("60", "4e-7", "1e-6", "1e-7", "false")
        sections["Output"].update({"Statistics interval": "7", "Field interval": "0"})
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
        # The results average the rows written.
        w = st["time"] >= s["results"]["averaging_start"]
        np.testing.assert_allclose(s["results"]["normal_force_mean"], st["lower_wall_normal_force"][w].mean(),
                                   rtol=1e-12)


class SolveStoppedShort(TempDirTestCase):
    """A step whose contact solve stops short is a warning naming the solve that stopped:
    a global method by its law residual and target, NLGS by its own norm."""

    WARNING = r"^warning: step (\d+) \(t = (\S+) s\): "

    def run_short(self, solver):
        sections = shear_sections("60", "4e-7", "1e-6", "1e-7", "false", Solver=solver)
        sections["Output"]["Field interval"] = "0"
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = read_json(os.path.join(self.tmp, "out", "summary.json"))
        _, st = read_csv(os.path.join(self.tmp, "out", "statistics.csv"))
        with open(os.path.join(self.tmp, "out", "log.txt")) as f:
            warnings = [l for l in f.read().splitlines() if l.startswith("warning: step")]
        # Steps not converged: as many as the rows say, at most ten of them as lines.
        n = int((st["solver_converged"] == 0).sum())
        self.assertGreater(n, 0, "one factorisation / one sweep cannot solve every step")
        self.assertEqual(s["solver_non_converged_steps"], n)
        self.assertEqual(len(warnings), min(n, 10))
        if n >= 10:
            self.assertTrue(warnings[-1].endswith(" (further warnings only counted)"), warnings[-1])
        return warnings, st

    def test_interior_point(self):
        """One factorisation per step: the warning gives the method, its law residual (the
        statistics row's, above the target) and the factorisations done."""
        warnings, st = self.run_short({"Method": "interior-point", "Maximum factorizations": "1",
                                       "Predictor sweeps": "0"})
        for line in warnings:
            m = re.match(self.WARNING + r"Solver/Method = interior-point stopped at law residual (\S+) "
                         r"\(Solver/Residual target = 0\.001\) after 1 factorisations"
                         r"( \(further warnings only counted\))?$", line)
            self.assertTrue(m, line)
            row = list(st["step"]).index(int(m.group(1)))
            self.assertEqual(st["solver_converged"][row], 0)
            self.assertAlmostEqual(float(m.group(3)) / st["law_residual"][row], 1, delta=1e-5)
            self.assertGreater(float(m.group(3)), 1e-3)

    def test_nlgs(self):
        """One sweep per step: the warning is NLGS's, with its sweeps and its own norm."""
        warnings, st = self.run_short({"Method": "nlgs", "Maximum iterations": "1", "Check interval": "1"})
        for line in warnings:
            m = re.match(self.WARNING + r"NLGS did not converge in 1 sweeps, residual (\S+)"
                         r"( \(further warnings only counted\))?$", line)
            self.assertTrue(m, line)
            row = list(st["step"]).index(int(m.group(1)))
            self.assertAlmostEqual(float(m.group(3)) / st["solver_residual"][row], 1, delta=1e-5)


class FailedRun(TempDirTestCase):
    """A run that cannot go on: exit 1, status failed, the reason in summary and log; no plots."""

    def test_failed(self):
        # A detection distance longer than half the period: the contact search refuses.
        sections = shear_sections("60", "4e-7", "1e-6", "1e-7", "true",
                                  **{"Contact law": {"Detection distance": "1e-5"}})
        write_prm(os.path.join(self.tmp, "case.prm"), sections)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        out = os.path.join(self.tmp, "out")
        self.assertEqual(r.returncode, 1, r.stderr)
        s = read_json(os.path.join(out, "summary.json"))
        self.assertEqual(s["status"], "failed")
        self.assertIn("period along x", s["error"])
        self.assertEqual(s["steps"], 0)
        self.assertEqual(s["results"], {})
        with open(os.path.join(out, "log.txt")) as f:
            log = f.read()
        self.assertIn("status failed", log)
        self.assertIn("error: " + s["error"], log)
        with h5py.File(os.path.join(out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            self.assertEqual(f["statistics"].attrs["n_rows"], 0)
        self.assertEqual(tmp_files(out), [])
        self.assertEqual(s["n_field_snapshots"], 2)
        self.assertEqual(sorted(os.listdir(out)), sorted(FILES + ["profiles.csv"]), "a failed run makes no plots")


if __name__ == "__main__":
    tribo_cli.main()
