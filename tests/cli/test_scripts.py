"""The analysis scripts of scripts/ on files whose answer is known."""

import os
import subprocess
import sys

import numpy as np

from tribo_cli import TempDirTestCase, main, read_png

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPTS = os.path.join(HERE, "..", "..", "scripts")
COLUMNS = ("vx", "solid_fraction", "sigma_xy", "granular_temperature")


def write_profiles(directory, layers, shifts=None, stderr=0.1):
    """A profiles.csv of @p layers layers: every column 1 + shift (shifts: {column: {layer:
    value}}), every standard error @p stderr."""
    os.makedirs(directory)
    names = ["layer", "y_over_h"] + list(COLUMNS) + [c + "_stderr" for c in COLUMNS]
    with open(os.path.join(directory, "profiles.csv"), "w") as f:
        f.write(",".join(names) + "\n")
        for i in range(layers):
            values = [i, (i + 0.5) / layers]
            values += [1 + (shifts or {}).get(c, {}).get(i, 0.0) for c in COLUMNS]
            values += [stderr] * len(COLUMNS)
            f.write(",".join(repr(float(v)) for v in values) + "\n")


def compare_profiles(*args):
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare_profiles.py")] + list(args),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=120)


class CompareProfiles(TempDirTestCase):
    def test_differences_in_combined_standard_errors(self):
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        write_profiles(a, 5)
        # vx: layer 2 higher by 0.3 and layer 4 lower by 0.1, against a combined error of
        # sqrt(2) 0.1: z = 2.121 and -0.707; the other columns equal.
        write_profiles(b, 5, {"vx": {2: 0.3, 4: -0.1}})
        png = os.path.join(self.tmp, "overlay.png")
        r = compare_profiles(a, b, "--labels", "A,B", "--plot", png)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {line.split("|")[1].strip(): [cell.strip() for cell in line.split("|")[2:5]]
                for line in r.stdout.splitlines() if line.startswith("| ") and not line.startswith("| column")}
        self.assertEqual(rows["vx"], ["2.12", "1", "%+.2f" % ((2.1213 - 0.7071) / 5)])
        for c in ("solid_fraction", "sigma_xy", "granular_temperature"):
            self.assertEqual(rows[c], ["0.00", "0", "+0.00"])
        self.assertIn("B against A, 5 layers", r.stdout)
        image = read_png(self, png)
        self.assertGreater(image.shape[1], image.shape[0])  # four panels side by side

    def test_a_control_pair_measures_how_far_the_batch_errors_understate_realisations(self):
        a, b, c, d = (os.path.join(self.tmp, n) for n in "abcd")
        write_profiles(a, 5)
        write_profiles(b, 5, {"vx": {2: 0.3, 4: -0.1}})  # z = 2.121 and -0.707, as above
        # The control pair: vx differs by +-2 combined errors in every layer (k = 2), the
        # solid fraction by 0.5 of one in layer 0 (root mean square 0.22: k = 1, not below).
        e = 0.1 * np.sqrt(2)
        write_profiles(c, 5)
        write_profiles(d, 5, {"vx": {i: 2 * e * (-1) ** i for i in range(5)}, "solid_fraction": {0: 0.5 * e}})
        r = compare_profiles(a, b, "--control", c, d)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {line.split("|")[1].strip(): [cell.strip() for cell in line.split("|")[2:9]]
                for line in r.stdout.splitlines() if line.startswith("| ") and not line.startswith("| column")}
        zmean = (2.1213 - 0.7071) / 5
        self.assertEqual(rows["vx"], ["2.12", "1", "%+.2f" % zmean, "2.00", "1.06", "0", "%+.2f" % (zmean / 2)])
        self.assertEqual(rows["solid_fraction"], ["0.00", "0", "+0.00", "1.00", "0.00", "0", "+0.00"])
        self.assertIn("control: " + d + " against " + c, r.stdout)

    def test_a_control_with_other_layers_is_refused(self):
        a, b, c, d = (os.path.join(self.tmp, n) for n in "abcd")
        for run in (a, b, c):
            write_profiles(run, 5)
        write_profiles(d, 6)
        r = compare_profiles(a, b, "--control", c, d)
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(d, "profiles.csv") + ": 6 layers, " + os.path.join(a, "profiles.csv") +
                      " has 5: the runs must have the same layers", r.stderr)

    def test_mismatched_layers_are_refused(self):
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        write_profiles(a, 5)
        write_profiles(b, 4)
        r = compare_profiles(a, b)
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(b, "profiles.csv") + ": 4 layers, " + os.path.join(a, "profiles.csv") +
                      " has 5: the runs must have the same layers", r.stderr)

    def test_a_missing_column_is_named(self):
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        write_profiles(a, 3)
        os.makedirs(b)
        with open(os.path.join(b, "profiles.csv"), "w") as f:
            f.write("layer,y_over_h,vx\n0,0.5,1.0\n")
        r = compare_profiles(a, b)
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(b, "profiles.csv") + ": expected the columns solid_fraction", r.stderr)


def write_statistics(directory, mu, load=4000.0, dt=1e-7):
    """A statistics.csv with one row per value of @p mu, every dt seconds from 0: the lower
    wall carries 1.01 load on even rows and 0.99 on odd ones."""
    os.makedirs(directory)
    with open(os.path.join(directory, "statistics.csv"), "w") as f:
        f.write("time,step,mu,normal_force,lower_wall_normal_force,max_overlap\n")
        for i, m in enumerate(mu):
            f.write(f"{i * dt!r},{i},{float(m)!r},{load!r},{load * (1.01 if i % 2 == 0 else 0.99)!r},{1e-9 * i!r}\n")


def compare_friction(*args):
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare_friction.py")] + list(args),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=120)


class CompareFriction(TempDirTestCase):
    def test_means_errors_and_differences(self):
        # 40 rows in the window. Run a: its 10 batches of 4 rows alternate 0.09 and 0.11,
        # so mu = 0.1 with the standard error of those ten means; run b is a + 0.02, so the
        # difference is 0.02 with a combined error sqrt(2) times a's.
        a_mu = np.repeat([0.09, 0.11] * 5, 4)
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        write_statistics(a, np.concatenate([[5.0] * 10, a_mu]))  # 10 rows before the window
        write_statistics(b, np.concatenate([[5.0] * 10, a_mu + 0.02]))
        r = compare_friction("1", "4.95", a, b)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = [line.split("|")[1:-1] for line in r.stdout.splitlines() if line.startswith("| ")]
        se10 = np.std([0.09, 0.11] * 5, ddof=1) / np.sqrt(10)
        self.assertEqual(rows[1][1].strip(), "40, 1.00-4.90")
        self.assertEqual(rows[1][2].strip(), "0.1000 +/- %.4f" % se10)
        self.assertEqual(rows[2][2].strip(), "0.1200 +/- %.4f" % se10)
        self.assertEqual(rows[1][4].strip(), "1.0000 +/- 0.0000")  # 1.01 and 0.99 alternate within batches
        self.assertEqual(rows[1][5].strip(), "4.900e-08")
        diff = rows[-1]
        self.assertEqual(diff[1].strip(), "+0.0200")
        self.assertTrue(diff[3].strip().startswith("%+.1f / " % (0.02 / (np.sqrt(2) * se10))))

    def test_a_window_outside_a_run_is_named(self):
        a = os.path.join(self.tmp, "a")
        write_statistics(a, [0.1] * 20)
        r = compare_friction("5", "9", a)
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(a, "statistics.csv") + ": 0 rows in 5-9 us (the run holds 0-1.9 us); "
                      "at least 4 are needed", r.stderr)

    def test_a_missing_column_is_named(self):
        a = os.path.join(self.tmp, "a")
        os.makedirs(a)
        with open(os.path.join(a, "statistics.csv"), "w") as f:
            f.write("time,mu\n0,0.1\n1e-7,0.1\n")
        r = compare_friction("0", "1", a)
        self.assertEqual(r.returncode, 2)
        self.assertIn(os.path.join(a, "statistics.csv") + ": expected the columns normal_force, "
                      "lower_wall_normal_force, max_overlap", r.stderr)


def reproduction(*args):
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, "reproduction.py")] + list(args),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=120)


def write_reference(runs, sigma_yy, sigma_yy_stderr):
    """A tradeoff_default study whose reference has the given sigma_yy (MPa), sigma_xy 11.5
    +/- 0.1 MPa, a linear profile of 10 layers from V = 5 m/s to 0 and epsilon 6e-10 m (1e-3 of a 0.6 um radius)
    before and 1.2e-10 m (2e-4 of it) in its averaging window."""
    case = os.path.join(runs, "tradeoff_default", "case_000")
    os.makedirs(case)
    columns = {"case": "0", "knob": "reference", "value": "Solver/Method = interior-point", "status": "complete",
               "mu_mean": "0.115", "mu_stderr": "0.001", "sigma_yy_mean": str(sigma_yy * 1e6),
               "sigma_yy_stderr": str(sigma_yy_stderr * 1e6), "sigma_xy_mean": "11.5e6", "sigma_xy_stderr": "1e5",
               "power_balance_ratio": "1.001", "power_balance_ratio_stderr": "0.005", "directory": "case_000"}
    with open(os.path.join(runs, "tradeoff_default", "study_summary.csv"), "w") as f:
        f.write(",".join(columns) + "\n" + ",".join(columns.values()) + "\n")
    with open(os.path.join(case, "profiles.csv"), "w") as f:
        f.write("layer,y_over_h,vx\n")
        for i in range(10):
            f.write("%d,%r,%r\n" % (i, (i + 0.5) / 10, 5 * (1 - (i + 0.5) / 10)))
    with open(os.path.join(case, "summary.json"), "w") as f:
        f.write('{"results": {"averaging_start": 1e-6}}')
    with open(os.path.join(case, "parameters.prm"), "w") as f:
        f.write("subsection SPH slider\n  set Sliding velocity = 1\nend\n"
                "subsection Shear cell\n  set Sliding velocity = 5 # m/s\nend\n")
    with open(os.path.join(case, "statistics.csv"), "w") as f:
        f.write("time,epsilon\n")
        for i in range(20):
            f.write("%r,%r\n" % (i * 1e-7, 6e-10 if i < 10 else -1.2e-10))


def write_paper_reference(runs, name, figures):
    """A tradeoff RUNS/name whose reference has @p figures: "mu,mu_se,sigma_xy,sigma_xy_se"."""
    os.makedirs(os.path.join(runs, name))
    with open(os.path.join(runs, name, "study_summary.csv"), "w") as f:
        f.write("case,knob,value,status,mu_mean,mu_stderr,sigma_xy_mean,sigma_xy_stderr,directory\n"
                "0,reference,x,complete,%s,case_000\n" % figures)


def write_shear_study(runs, name, columns, cases):
    """A study RUNS/name whose cases are {column: value} with mu_mean, mu_stderr, status,
    error, and "eps" (mean |epsilon| in its window, m) and "profile" ((vx/V at 1/4, at 3/4),
    linear between (0, 1) and (1, 0)) for each case's statistics.csv and profiles.csv."""
    os.makedirs(os.path.join(runs, name))
    header = ["case"] + columns + ["status", "mu_mean", "mu_stderr", "error", "directory"]
    lines = [",".join(header)]
    for k, c in enumerate(cases):
        directory = os.path.join(runs, name, "case_%03d" % k)
        os.makedirs(directory)
        lines.append(",".join([str(k)] + [c[col] for col in columns] +
                              [c.get("status", "complete"), str(c["mu"]), str(c.get("mu_se", 0.002)),
                               c.get("error", ""), "case_%03d" % k]))
        with open(os.path.join(directory, "summary.json"), "w") as f:
            f.write('{"results": {"averaging_start": 0}}')
        with open(os.path.join(directory, "statistics.csv"), "w") as f:
            f.write("time,epsilon\n" + "".join("%r,%r\n" % (i * 1e-7, c.get("eps", 1e-11) * (1 + 0.01 * (i % 3 - 1)))
                                                for i in range(40)))
        quarter, three_quarters = c.get("profile", (0.75, 0.25))
        ys = [(i + 0.5) / 10 for i in range(10)]
        vs = np.interp(ys, [0, 0.25, 0.75, 1], [1, quarter, three_quarters, 0])
        with open(os.path.join(directory, "profiles.csv"), "w") as f:
            f.write("layer,y_over_h,vx,vx_stderr\n" + "".join("%d,%r,%r,0.1\n" % (i, y, 5 * v)
                                                                for i, (y, v) in enumerate(zip(ys, vs))))
        with open(os.path.join(directory, "parameters.prm"), "w") as f:
            f.write("subsection Shear cell\n  set Sliding velocity = 5\nend\n")
    with open(os.path.join(runs, name, "study_summary.csv"), "w") as f:
        f.write("\n".join(lines) + "\n")


def reproduction_rows(stdout):
    """{quantity: (ours, verdict)} of the table."""
    rows = [line.split(" | ") for line in stdout.splitlines() if line.startswith("| ") and "---" not in line]
    return {r[2]: (r[4], r[6].rstrip(" |")) for r in rows[1:]}


class Reproduction(TempDirTestCase):
    def test_verdicts_from_the_reference_run(self):
        write_reference(self.tmp, 100.1, 0.1)
        r = reproduction(self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = reproduction_rows(r.stdout)
        self.assertEqual(rows["sigma_yy across the gap"], ("100.1 +/- 0.1 MPa", "reproduced"))
        self.assertEqual(rows["power balance in steady state"][1], "reproduced")
        self.assertEqual(rows["gap residue epsilon (IQS)"],
                         ("mean abs(epsilon) = 2.0e-04 of the mean radius", "reproduced"))
        ours, verdict = rows["velocity profile without cohesion, rigid walls"]
        self.assertTrue(ours.startswith("rms deviation from a line 0.000 V; two layers at each wall carry 22% and 22%"),
                        ours)
        self.assertEqual(verdict, "reproduced")
        self.assertTrue(rows["sigma_xy without cohesion (IQS, 100 MPa, 5 m/s)"][1]
                        .startswith("not reproduced: 2.3 times the paper's"))
        # the studies that are not there
        self.assertEqual(rows["sigma_xy at gamma = 0.5"], ("not run", "not run"))

    def test_a_layer_that_does_not_move_is_called_a_plug(self):
        write_reference(self.tmp, 100.0, 0.1)
        case = os.path.join(self.tmp, "touching_walls", "case_000")
        os.makedirs(case)
        with open(os.path.join(self.tmp, "touching_walls", "study_summary.csv"), "w") as f:
            f.write("case,Shear cell/Wall discs,status,sigma_xy_mean,sigma_xy_stderr,directory\n"
                    "0,41,complete,6.3e6,1.5e5,case_000\n")
        with open(os.path.join(case, "profiles.csv"), "w") as f:
            f.write("layer,y_over_h,vx\n" + "".join("%d,%r,0.01\n" % (i, (i + 0.5) / 10) for i in range(10)))
        with open(os.path.join(case, "parameters.prm"), "w") as f:
            f.write("subsection Shear cell\n  set Sliding velocity = 5\nend\n")
        verdict = reproduction_rows(reproduction(self.tmp).stdout)["sigma_xy without cohesion (IQS, 100 MPa, 5 m/s)"][1]
        self.assertIn("walls of touching 0.96 um discs give 6.3 +/- 0.15 MPa, with the layer a plug that the lower "
                      "wall slides under", verdict)

    def test_the_paper_size_reference_joins_the_friction_row(self):
        write_reference(self.tmp, 100.0, 0.1)
        write_paper_reference(self.tmp, "tradeoff_paper_solver", "0.1164,0.001,11.64e6,1e5")
        ours = reproduction_rows(reproduction(self.tmp).stdout)["sigma_xy without cohesion (IQS, 100 MPa, 5 m/s)"][0]
        self.assertTrue(ours.endswith("at the paper's size (3820 grains), interior point 1e-8: 11.64 +/- 0.1 MPa "
                                      "(mu 0.1164 +/- 0.001)"), ours)
        # and the paper's sample at the finer step, when its ladder has run
        write_paper_reference(self.tmp, "tradeoff_paper_step", "0.1096,0.0008,10.98e6,5e4")
        ours = reproduction_rows(reproduction(self.tmp).stdout)["sigma_xy without cohesion (IQS, 100 MPa, 5 m/s)"][0]
        self.assertTrue(ours.endswith("; at h = 2e-9 s (APGS 3e-5, within one error of converged): 10.98 +/- 0.05 MPa "
                                      "(mu 0.1096 +/- 0.0008)"), ours)

    def test_the_sph_friction_verdict_names_the_drive_within_two_combined_errors(self):
        # mu_l 0.06 +/- 0.01 (the paper's) against the reset drive's 0.075 +/- 0.005 at both
        # gamma: |diff| 0.015 < 2 hypot(0.005, 0.01) = 0.022, reproduced; the exact drive's
        # 0.002 is not.
        os.makedirs(os.path.join(self.tmp, "sph_numerics"))
        rows = ["case,SPH slider/Gamma,SPH slider/Drive,SPH slider/Interface viscosity,status,mu_mean,mu_stderr"]
        for k, (gamma, drive, mu) in enumerate([("1e6", "exact", 0.002), ("1e8", "exact", 0.04),
                                               ("1e6", "reset", 0.075), ("1e8", "reset", 0.075)]):
            rows.append("%d,%s,%s,false,complete,%r,0.005" % (k, gamma, drive, mu))
        with open(os.path.join(self.tmp, "sph_numerics", "study_summary.csv"), "w") as f:
            f.write("\n".join(rows) + "\n")
        ours, verdict = reproduction_rows(reproduction(self.tmp).stdout)[
            "mu_l at 1e8 Pa, 1 m/s, alpha = 0.1, flat over gamma = 1e6-1e9"]
        self.assertEqual(ours, "exact drive: gamma 1e6 0.002 +/- 0.005, 1e8 0.04 +/- 0.005; "
                               "reset drive: gamma 1e6 0.075 +/- 0.005, 1e8 0.075 +/- 0.005")
        self.assertEqual(verdict, "reproduced under a reading: the reset drive")

    def write_law_studies(self):
        """IQS and ELAS under both readings of gamma: ELAS +12 % at eta 2 (0.2 d), +88 % at eta 4
        and stopped at eta 8 (0.02 d); mean |epsilon| ratios 0.8, 2.0 (eta 4), 1.2, 1.5."""
        law = ["Contact law/Law", "Contact law/Cohesion"]
        write_shear_study(self.tmp, "laws_cohesion", law, [
            {"Contact law/Law": "IQS", "Contact law/Cohesion": "0", "mu": 0.115, "eps": 2e-11},
            {"Contact law/Law": "IQS", "Contact law/Cohesion": "480", "mu": 0.33, "eps": 1e-11, "profile": (0.68, 0.14)},
            {"Contact law/Law": "IQS", "Contact law/Cohesion": "960", "mu": 0.51, "eps": 1e-11},
            {"Contact law/Law": "ELAS", "Contact law/Cohesion": "0", "mu": 0.092, "eps": 1.6e-11},
            {"Contact law/Law": "ELAS", "Contact law/Cohesion": "480", "mu": 0.62, "eps": 2e-11},
            {"Contact law/Law": "ELAS", "Contact law/Cohesion": "960", "mu": 1.3, "status": "failed",
             "error": "an overlap of 4.8e-07 m"}])
        write_shear_study(self.tmp, "laws_cohesion_range", law, [
            {"Contact law/Law": "IQS", "Contact law/Cohesion": "120", "mu": 0.30, "eps": 1e-11},
            {"Contact law/Law": "IQS", "Contact law/Cohesion": "240", "mu": 0.48, "eps": 1e-11},
            {"Contact law/Law": "ELAS", "Contact law/Cohesion": "120", "mu": 0.29, "eps": 1.2e-11},
            {"Contact law/Law": "ELAS", "Contact law/Cohesion": "240", "mu": 0.5376, "eps": 1.5e-11}])

    def test_the_laws_rows_give_each_reading_its_verdict(self):
        self.write_law_studies()
        rows = reproduction_rows(reproduction(self.tmp).stdout)
        ours, verdict = rows["mu of IQS against ELAS, 0-1 cohesion"]
        self.assertIn("eta 2: IQS 0.48 +/- 0.002, ELAS 0.5376 +/- 0.002, ratio 1.12 +/- 0.01", ours)
        self.assertIn("0.02 d: ELAS stops at gamma = 1 (eta 8); with less cohesion it lies +88% to +88% from IQS "
                      "(not reproduced)", verdict)
        self.assertIn("0.2 d: at gamma = 1 (eta 2) ELAS +12% +/- 1% (reproduced)", verdict)
        self.assertIn("at gamma = 0 ELAS -20% +/- 2%", verdict)
        ours, verdict = rows["epsilon_ELAS / epsilon_IQS"]
        self.assertIn("0.02 d: eta 0 0.80 +/- 0.00; eta 4 2.00 +/- 0.00. 0.2 d: eta 1 1.20 +/- 0.00; eta 2 1.50", ours)
        self.assertIn("0.02 d: above 1 with cohesion, growing with eta; 0.2 d: above 1 with cohesion, growing", verdict)

    def test_accommodation_moves_to_the_lower_interface_under_a_soft_body(self):
        self.write_law_studies()
        body = ["Shear cell/Upper body Young's modulus", "Contact law/Cohesion"]
        write_shear_study(self.tmp, "accommodation", body, [
            {body[0]: "1e11", body[1]: "0", "mu": 0.11}, {body[0]: "3e9", body[1]: "0", "mu": 0.11},
            {body[0]: "1e11", body[1]: "480", "mu": 0.3, "profile": (0.80, 0.41)},
            {body[0]: "3e9", body[1]: "480", "mu": 0.3, "profile": (0.58, 0.10)}])
        ours, verdict = reproduction_rows(reproduction(self.tmp).stdout)[
            "velocity accommodation with the upper body's stiffness"]
        self.assertIn("eta 4: rigid 0.32 +/- 0.02 / 0.14 +/- 0.02, E1 0.20 +/- 0.02 / 0.41 +/- 0.02, "
                      "E2 0.42 +/- 0.02 / 0.10 +/- 0.02", ours)
        self.assertTrue(verdict.startswith("reproduced under a reading (gamma = 0.5 as eta = 4): the soft body moves "
                                           "the velocity drop to the lower interface (TB/LB; E2 - E1 +7.8 errors)"),
                        verdict)
        # A soft body that changes nothing is not the paper's
        os.remove(os.path.join(self.tmp, "accommodation", "case_003", "profiles.csv"))
        with open(os.path.join(self.tmp, "accommodation", "case_003", "profiles.csv"), "w") as f:
            f.write("layer,y_over_h,vx,vx_stderr\n" + "".join("%d,%r,%r,0.1\n" % (i, (i + 0.5) / 10, 5 * (
                0.8 if i == 2 else 0.41 if i == 7 else 0.5)) for i in range(10)))
        verdict = reproduction_rows(reproduction(self.tmp).stdout)[
            "velocity accommodation with the upper body's stiffness"][1]
        self.assertTrue(verdict.startswith("not reproduced"), verdict)

    def test_a_load_two_errors_off_is_not_reproduced(self):
        write_reference(self.tmp, 100.3, 0.1)
        rows = reproduction_rows(reproduction(self.tmp).stdout)
        self.assertEqual(rows["sigma_yy across the gap"][1], "not reproduced")

    def test_an_unreadable_run_names_its_row_and_keeps_the_table(self):
        write_reference(self.tmp, 100.0, 0.1)
        os.remove(os.path.join(self.tmp, "tradeoff_default", "case_000", "profiles.csv"))
        table = os.path.join(self.tmp, "reproduction.md")
        with open(table, "w") as f:
            f.write("the last table\n")
        r = reproduction(self.tmp, table)
        self.assertEqual(r.returncode, 2)
        self.assertIn("the row 'velocity profile without cohesion, rigid walls' cannot be read: "
                      "FileNotFoundError", r.stderr)
        self.assertIn(os.path.join("case_000", "profiles.csv"), r.stderr)
        with open(table) as f:
            self.assertEqual(f.read(), "the last table\n")
        self.assertFalse(os.path.exists(table + ".tmp"))

    def test_the_output_file_holds_the_table(self):
        write_reference(self.tmp, 100.1, 0.1)
        table = os.path.join(self.tmp, "reproduction.md")
        self.assertEqual(reproduction(self.tmp, table).returncode, 0)
        with open(table) as f:
            self.assertEqual(reproduction_rows(f.read())["sigma_yy across the gap"], ("100.1 +/- 0.1 MPa", "reproduced"))

    def test_without_runs_nothing_is_claimed(self):
        r = reproduction(self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = reproduction_rows(r.stdout)
        self.assertEqual(rows["sigma_yy across the gap"], ("not run", "not run"))
        self.assertEqual(len(rows), 20)
        self.assertEqual(reproduction(os.path.join(self.tmp, "missing")).returncode, 2)


if __name__ == "__main__":
    main()
