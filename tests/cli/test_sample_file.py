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

    def test_one_wall_only(self):
        rows = [r for r in sample_rows() if r[3] != "upper_wall"]
        self.check_file(rows, "rows for the lower wall only: give both walls, or neither")

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

    def test_walls_generated_around_a_sample_of_grains(self):
        rows = sample_rows(walls=False)
        summary, stats = self.run_sample(rows)
        # L / d discs per wall, d the default Mean diameter 1.2 um, placed clear of the grains.
        self.assertEqual(summary["n_discs"] - len(rows), 2 * round(L / 1.2e-6))
        self.assertEqual(float(stats[0]["max_overlap"]), 0.0)
        self.assertGreater(float(stats[0]["gap"]), 2.2 * 2 * R)


if __name__ == "__main__":
    tribo_cli.main()
