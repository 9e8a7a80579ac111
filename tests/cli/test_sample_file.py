#!/usr/bin/python3
"""Shear cell/Sample file (app/sample_file.h): a sample read from a CSV file starts the
run with exactly its discs, and each kind of bad file stops before anything is written
with the file, line and column in a one-line message (exit 2).

Usage: test_sample_file.py PATH/TO/tribo
"""
import csv
import json
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from test_bad_input import BadInputTestCase  # noqa: E402
from tribo_cli import run, write_prm  # noqa: E402

L, R = 1.2e-5, 0.5e-6  # period and disc radius, m


def shear_case(sample="sample.csv", end_time="2e-8"):
    return {
        "Simulation": {"Scene": "shear", "Time step": "2e-9", "End time": end_time},
        "Shear cell": {"Sample file": sample, "Length": str(L), "Wall discs": "0", "Pressure": "1e8",
                       "Pressure ramp time": "0", "Shear start": "0", "Sliding velocity": "1"},
        "Output": {"Field interval": "0", "Plots": "false", "Statistics interval": "1"},
    }


def sample_rows(walls=True):
    """Two rows of 10 grains 1.2 diameters apart between two walls of 12 discs, all of
    radius R, nothing touching (the walls 0.05 R clear of the grains); the grains carry a
    velocity and a spin."""
    d, rows = 2 * R, []
    for j in range(2):
        for i in range(10):
            rows.append(((i + 0.5) * 1.2 * d, d + j * 1.2 * d, R, "grain", 0.1 * j, -0.2, 3.0))
    if walls:
        for i in range(12):
            rows.append(((i + 0.5) * d, -0.05 * R, R, "lower_wall", 0, 0, 0))
            rows.append(((i + 0.5) * d, 2.2 * d + R + 1.05 * R, R, "upper_wall", 0, 0, 0))
    return rows


def write_sample(path, rows, header="x,y,r,body,vx,vy,spin"):
    with open(path, "w") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(",".join(repr(v) if not isinstance(v, str) else v for v in r) + "\n")


class BadSampleFiles(BadInputTestCase):
    def check_file(self, rows, expected, line=None, header="x,y,r,body,vx,vy,spin", text=None):
        path = os.path.join(self.tmp, "sample.csv")
        if text is not None:
            with open(path, "w") as f:
                f.write(text)
        else:
            write_sample(path, rows, header)
        msg, _ = self.run_bad_case(shear_case())
        self.assert_parts(msg, "sample.csv" + (":%d:" % line if line else ":"), expected)
        self.assertTrue(os.path.exists(path), "the sample itself is left alone")

    def test_missing_file(self):
        msg, where = self.run_bad_case(shear_case("no_such.csv"))
        self.assert_parts(msg, "no_such.csv", "cannot open the sample file")

    def test_bad_header(self):
        self.check_file(sample_rows(), "expected the header 'x,y,r,body' or 'x,y,r,body,vx,vy,spin'",
                        1, header="x,y,radius,body")

    def test_non_positive_radius(self):
        rows = sample_rows()
        rows[2] = rows[2][:2] + (-1e-7,) + rows[2][3:]
        self.check_file(rows, "column 'r': expected a positive radius in m, got '-1e-07'", 4)

    def test_non_numeric_cell(self):
        text = "x,y,r,body\n1e-6,1e-6,5e-7,grain\n2e-6,abc,5e-7,grain\n"
        self.check_file(None, "column 'y': expected a finite number, got 'abc'", 3, text=text)

    def test_wrong_number_of_cells(self):
        text = "x,y,r,body\n1e-6,1e-6,5e-7\n"
        self.check_file(None, "expected 4 cells (x,y,r,body), got 3", 2, text=text)

    def test_unknown_body(self):
        text = "x,y,r,body\n1e-6,1e-6,5e-7,wall\n"
        self.check_file(None, "column 'body': expected grain, lower_wall or upper_wall, got 'wall'", 2, text=text)

    def test_grain_outside_the_period(self):
        rows = sample_rows()
        rows[5] = (L,) + rows[5][1:]
        self.check_file(rows, "column 'x': expected a grain inside the period [0, 1.2e-05) m", 7)

    def test_no_grains(self):
        rows = [r for r in sample_rows() if r[3] != "grain"]
        self.check_file(rows, "no grain rows (body = grain)")

    def test_upper_wall_only(self):
        rows = [r for r in sample_rows() if r[3] != "lower_wall"]
        self.check_file(rows, "rows for the upper wall only: give the lower wall too, or neither")

    def test_overlapping_walls(self):
        rows = [r if r[3] != "upper_wall" else (r[0], 0.5 * R, R, r[3], 0, 0, 0) for r in sample_rows()]
        self.check_file(rows, "the walls overlap")


class SampleRun(tribo_cli.TempDirTestCase):
    def run_sample(self, rows):
        write_sample(os.path.join(self.tmp, "sample.csv"), rows)
        write_prm(os.path.join(self.tmp, "case.prm"), shear_case(end_time="2e-9"))
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "out", "summary.json")) as f:
            summary = json.load(f)
        with open(os.path.join(self.tmp, "out", "statistics.csv")) as f:
            stats = list(csv.DictReader(f))
        return summary, stats

    def test_the_run_starts_from_the_sample(self):
        rows = sample_rows()
        summary, stats = self.run_sample(rows)
        self.assertEqual(summary["n_discs"], len(rows))
        self.assertEqual(summary["n_bodies"], 20 + 2)  # grains plus two wall clumps
        # After one step (no contact: the walls stand 0.05 R clear), the upper wall has
        # fallen from its sample height by at most what P L over its mass gives in 2 ns.
        upper_y = sum(r[1] for r in rows if r[3] == "upper_wall") / 12
        self.assertAlmostEqual(float(stats[0]["upper_wall_y"]), upper_y, delta=1e-3 * R)
        # The grains' kinetic energy is the sample's: m (vx^2 + vy^2) / 2 + I w^2 / 2 each.
        m = 7800 * math.pi * R * R
        ke = sum(0.5 * m * (r[4] ** 2 + r[5] ** 2) + 0.25 * m * R * R * r[6] ** 2
                 for r in rows if r[3] == "grain")
        self.assertAlmostEqual(float(stats[0]["kinetic_energy_third_body"]) / ke, 1, delta=1e-3)

    def test_parameters_repeat_the_run_from_elsewhere(self):
        """parameters.prm names the sample by its absolute path: run from another directory,
        it starts from the same sample and repeats the first step exactly."""
        _, stats = self.run_sample(sample_rows())
        elsewhere = os.path.join(self.tmp, "elsewhere")
        os.makedirs(elsewhere)
        r = run(["run", os.path.join(self.tmp, "out", "parameters.prm"), "--output", "again", "--quiet"],
                cwd=elsewhere)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(elsewhere, "again", "statistics.csv")) as f:
            again = list(csv.DictReader(f))
        self.assertEqual(again[0], stats[0])

    def test_a_deformable_body_in_the_upper_walls_place(self):
        write_sample(os.path.join(self.tmp, "sample.csv"), sample_rows())
        case = shear_case(end_time="2e-9")
        case["Shear cell"]["Upper body model"] = "fem"
        write_prm(os.path.join(self.tmp, "case.prm"), case)
        r = run(["run", "case.prm", "--output", "out", "--quiet"], cwd=self.tmp)
        if "left out" in r.stderr:
            self.skipTest("built without TRIBO_WITH_FEM")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "out", "summary.json")) as f:
            summary = json.load(f)
        self.assertEqual(summary["n_discs"], 20 + 12)  # the grains and the lower wall: the body replaces the upper
        with open(os.path.join(self.tmp, "out", "statistics.csv")) as f:
            first = list(csv.DictReader(f))[0]
        # Its surface where the upper wall's was (2.2 d + R + 1.05 R - R), the lower wall's
        # surface at -0.05 R + R: the grains' area over that gap, after one step of 2 ns.
        surface_gap = (2.2 * 2 * R + 1.05 * R) - (-0.05 * R + R)
        self.assertAlmostEqual(float(first["solid_fraction"]) / (20 * math.pi * R * R / (surface_gap * L)), 1,
                               delta=1e-4)
        # Its final sample: the grains and the lower wall (the body is not made of discs).
        with open(os.path.join(self.tmp, "out", "sample_final.csv")) as f:
            bodies = [row["body"] for row in csv.DictReader(f)]
        self.assertEqual((bodies.count("grain"), bodies.count("lower_wall"), bodies.count("upper_wall")), (20, 12, 0))

    def test_walls_generated_around_a_sample_of_grains(self):
        rows = sample_rows(walls=False)
        summary, stats = self.run_sample(rows)
        # L / d discs per wall, d the default Mean diameter 1.2 um, placed clear of the grains.
        self.assertEqual(summary["n_discs"] - len(rows), 2 * round(L / 1.2e-6))
        self.assertEqual(float(stats[0]["max_overlap"]), 0.0)
        self.assertGreater(float(stats[0]["gap"]), 2.2 * 2 * R)


def state_case(end_time, time_step="2e-9", **shear):
    """shear_case() without a sample file, from the state in directory 'state'."""
    c = shear_case(end_time=end_time)
    c["Simulation"]["Time step"] = time_step
    del c["Shear cell"]["Sample file"]
    c["Shear cell"]["Initial state"] = "state"
    c["Shear cell"].update(shear)
    return c


class SnapshotsAndStates(BadInputTestCase):
    """`tribo sample DIR --time T` prints a snapshot as a sample file; Shear cell/Initial
    state = DIR goes on from a run's final state at its final time."""

    def make_state(self, out="state", end_time="2e-8", field_interval="4"):
        write_sample(os.path.join(self.tmp, "sample.csv"), sample_rows())
        case = shear_case(end_time=end_time)
        case["Output"]["Field interval"] = field_interval
        write_prm(os.path.join(self.tmp, "make.prm"), case)
        r = run(["run", "make.prm", "--output", out, "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_a_snapshot_printed_as_a_sample(self):
        self.make_state()  # 10 steps of 2 ns, snapshots at steps 0, 4, 8 and 10
        r = run(["sample", "state", "--time", "1.5e-8"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "state", "fields", "sample_00002.csv")) as f:
            self.assertEqual(r.stdout, f.read())  # the nearest snapshot: step 8, 1.6e-8 s
        self.assertIn("(t = 1.6e-08 s)", r.stderr)
        last = run(["sample", "state"], cwd=self.tmp)
        with open(os.path.join(self.tmp, "state", "sample_final.csv")) as f:
            self.assertEqual(last.stdout, f.read())
        # The grains of the step-8 snapshot: the sample's, moved by their velocity (no
        # contact: free flight) over 16 ns, to round-off.
        snap = list(csv.DictReader(r.stdout.splitlines()))
        grains = [row for row in sample_rows() if row[3] == "grain"]
        self.assertEqual(len([g for g in snap if g["body"] == "grain"]), len(grains))
        for g, row in zip([g for g in snap if g["body"] == "grain"], grains):
            self.assertAlmostEqual(float(g["x"]), row[0] + 1.6e-8 * row[4], delta=1e-9 * R)
            self.assertAlmostEqual(float(g["y"]), row[1] + 1.6e-8 * row[5], delta=1e-9 * R)

    def test_a_state_goes_on_as_the_run_would(self):
        self.make_state(out="whole", end_time="4e-8")
        self.make_state(out="state", end_time="2e-8")
        write_prm(os.path.join(self.tmp, "on.prm"), state_case("4e-8"))
        r = run(["run", "on.prm", "--output", "on", "--quiet"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.tmp, "on", "summary.json")) as f:
            summary = json.load(f)
        self.assertEqual((summary["steps"], summary["steps_planned"]), (10, 10))
        self.assertAlmostEqual(summary["start_time"], 2e-8, delta=1e-20)
        with open(os.path.join(self.tmp, "on", "statistics.csv")) as f:
            on = list(csv.DictReader(f))
        with open(os.path.join(self.tmp, "whole", "statistics.csv")) as f:
            whole = list(csv.DictReader(f))[10:]
        # Steps 11-20 of the whole run, to round-off: the walls falling under the full load
        # P L (ramp over), the lower wall sliding at V, the grains in flight.
        self.assertEqual([int(row["step"]) for row in on], list(range(11, 21)))
        for a, b in zip(on, whole):
            self.assertAlmostEqual(float(a["time"]), float(b["time"]), delta=1e-20)
            self.assertAlmostEqual(float(a["upper_wall_y"]), float(b["upper_wall_y"]), delta=1e-9 * R)
            self.assertAlmostEqual(float(a["upper_wall_vy"]), float(b["upper_wall_vy"]),
                                   delta=1e-9 * abs(float(b["upper_wall_vy"])))
            self.assertAlmostEqual(float(a["kinetic_energy_third_body"]), float(b["kinetic_energy_third_body"]),
                                   delta=1e-9 * float(b["kinetic_energy_third_body"]))
            self.assertEqual(a["normal_force"], b["normal_force"])

    def test_bad_states(self):
        self.make_state()
        msg, _ = self.run_bad_case(state_case("4e-8", time_step="3e-9"))
        self.assert_parts(msg, "entry 'Shear cell/Initial state'", "expected a state at a whole number of "
                          "time steps", "ends at t0 = 2e-08 s, 6.66667 steps of Simulation/Time step = 3e-09 s")
        msg, _ = self.run_bad_case(state_case("1e-8"))
        self.assert_parts(msg, "expected a state before Simulation/End time = 1e-08 s", "ends at t0 = 2e-08 s")
        msg, _ = self.run_bad_case(state_case("4e-8", **{"Sample file": "sample.csv"}))
        self.assert_parts(msg, "expected no initial state together with a Shear cell/Sample file")
        msg, _ = self.run_bad_case(state_case("4e-8", **{"Length": "1.3e-5"}))
        self.assert_parts(msg, "expected a run of this case's Shear cell/Length = 1.3e-05 m", "has 1.2e-05 m)")
        msg, _ = self.run_bad_case(state_case("4e-8", **{"Initial state": "nowhere"}))
        self.assert_parts(msg, "expected the directory of a completed shear run (",
                          "nowhere has no readable summary.json")
        msg = self.run_bad(["sample", "nowhere"])
        self.assert_parts(msg, "error: tribo sample nowhere: no snapshot index nowhere/fields/discs.pvd")
        msg = self.run_bad(["sample", "state", "--time", "soon"])
        self.assert_parts(msg, "error: --time 'soon': expected a time in s")
        msg = self.run_bad(["sample", "state", "--time"])
        self.assert_parts(msg, "error: --time needs a value (a time in s)")


if __name__ == "__main__":
    tribo_cli.main()
