#!/usr/bin/python3
"""Movable-lattice-particle scenes (Popov and Filippov 2006) against physics:

- a compression wave launched by a step load on the platen of a slab at rest crosses
  two probes at the longitudinal speed c_L = sqrt((lambda + 2 mu)/rho) of the linear
  theory (hexagonal) and sqrt(k_c/rho) (square, along an axis), within 3 %;
- a slab pressed between two platens oscillates elastically about a width near the
  elastic estimate 1 - P/E below a critical load, and flows plastically (delta_h far
  below the elastic estimate, down to the stroke limit) above it: the critical load is
  bracketed between two loads; the late mean width carries its batch-means standard
  error, recomputed here from the statistics;
- two rubbed beams: the contact-over-bulk |F_return| ratio equals the one recomputed
  from profiles.csv, with a positive batch-means standard error below half of it;
- random particles order into a lattice whose structure factor has six peaks 60 degrees
  apart (n = 6, at 30 + 60 k degrees for rows along x) or four 90 degrees apart (n = 4,
  at 0 + 90 k degrees) on the first Bragg ring;
- a target (E, nu) sets k_c and f0 through the mapping (over the explicit entries): the
  linear theory gives back E and the wave moves at its c_L;
- an interrupted run (SIGINT, SIGTERM) keeps its outputs and exits 128 + N; a run that
  flies apart ends as failed (exit 1) with the reason; a time step above the stable
  limit and an interface offset out of range are refused with the exact message
  and exit 2.

Usage: test_mlp_scenes.py PATH/TO/tribo
"""
import csv
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

TRIBO = None


def write_case(path, scene, mlp, sub, simulation=""):
    """Write a case file: Simulation/Scene, MLP entries and one scene subsection (MLP NAME)."""
    lines = ["subsection Simulation", "  set Scene = %s" % scene]
    lines += ["  " + l for l in simulation.splitlines() if l.strip()]
    lines += ["end", "subsection Output", "  set Plots = false", "end", "subsection MLP"]
    lines += ["  set %s = %s" % kv for kv in mlp.items()]
    lines += ["end"]
    if sub:
        name, entries = sub
        lines += ["subsection MLP %s" % name.lower()] + ["  set %s = %s" % kv for kv in entries.items()]
        lines += ["end"]
    lines += [""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def run(directory, name, scene, mlp, sub, simulation, timeout=300):
    """Run a case into directory/name; returns (returncode, summary, statistics columns)."""
    case = os.path.join(directory, name + ".prm")
    out = os.path.join(directory, name)
    write_case(case, scene, mlp, sub, simulation)
    p = subprocess.run([TRIBO, "run", case, "--output", out, "--quiet"], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=timeout)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return p, summary, statistics(out)


def statistics(out):
    with open(os.path.join(out, "statistics.csv")) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


# Slab of the compression tests: k_c = 1e9 Pa, f0 = 20 N/m (k_t = 0.12 k_c), a r0 = 7.
SLAB = {"Return force amplitude": 20, "Damping": 0.005, "Thermal energy": 1e-8,
        "Time step": 2e-10, "Statistics interval": 10}


class Wave(unittest.TestCase):
    """Step load on the platens of a 120 x 60 slab at T = 0, eta = 0, strain 1e-3."""

    def check(self, lattice):
        with tempfile.TemporaryDirectory() as d:
            p, s, _ = run(d, "wave", "mlp_compression",
                          {"Lattice": lattice, "Damping": 0, "Thermal energy": 0,
                           "Time step": 2e-10, "Statistics interval": 50},
                          ("Compression", {"Columns": 120, "Rows": 60, "Pressure": 1e6,
                                           "Density maps": 0, "First probe": 0.1,
                                           "Second probe": 0.45}),
                          "set End time = 1.6e-7")
            self.assertEqual(p.returncode, 0, p.stderr)
            r = s["results"]
            print("\n  %s: c measured %.2f m/s, theory %.2f m/s, ratio %.4f" %
                  (lattice, r["wave_speed"], r["longitudinal_speed_theory"], r["wave_speed_over_theory"]))
            self.assertAlmostEqual(r["wave_speed_over_theory"], 1.0, delta=0.03)

    def test_hexagonal_wave_travels_at_c_L(self):
        self.check("hexagonal")

    def test_square_wave_travels_at_sqrt_k_c_over_rho(self):
        self.check("square")


class Compression(unittest.TestCase):
    """40 x 20 hexagonal slab between platens, step load, 3 us."""

    LOW, HIGH = 1.0e8, 2.5e8

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.runs = {}
        for P in (cls.LOW, cls.HIGH):
            cls.runs[P] = run(cls.dir.name, "slab_%g" % P, "mlp_compression", SLAB,
                              ("Compression", {"Pressure": P, "Density maps": 3}),
                              "set End time = 3e-6")

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_elastic_oscillation_below_the_critical_load(self):
        p, s, st = self.runs[self.LOW]
        self.assertEqual(p.returncode, 0, p.stderr)
        r = s["results"]
        strain = r["elastic_strain"]
        late = st["delta_h"][st["time"] >= 1.5e-6]
        mean = late.mean()
        # Static width near the linear estimate (the Morse bonds stiffen under
        # compression and the slab is hotter than T: measured 0.6 P/E).
        self.assertGreater((1 - mean) / strain, 0.3)
        self.assertLess((1 - mean) / strain, 1.2)
        # Never beyond the dynamic overshoot 1 - 2 P/E; oscillating about the mean.
        self.assertGreater(st["delta_h"].min(), 1 - 2.2 * strain)
        crossings = np.count_nonzero(np.diff(np.sign(late - mean)) != 0)
        self.assertGreaterEqual(crossings, 6)
        self.assertFalse(r["stopped_by_stroke"])
        # summary's late mean (t >= 0.7 t_end) and its batch-means standard error: 10
        # contiguous batches of the rows, sqrt(sum (m_b - m)^2 / (B (B - 1))).
        rows = st["delta_h"][st["time"] >= 0.7 * st["time"][-1]]
        n = len(rows)
        batches = np.array([rows[b * n // 10:(b + 1) * n // 10].mean() for b in range(10)])
        se = math.sqrt(((batches - batches.mean()) ** 2).sum() / (10 * 9))
        self.assertAlmostEqual(r["delta_h_late_mean"], rows.mean(), delta=1e-12)
        self.assertAlmostEqual(r["delta_h_late_stderr"], se, delta=1e-9 * se)
        self.assertGreater(se, 0)
        print("\n  P = %g Pa: P/E = %.4f, late delta_h %.4f (1 - %.2f P/E), min %.4f, %d crossings" %
              (self.LOW, strain, mean, (1 - mean) / strain, st["delta_h"].min(), crossings))

    def test_plastic_flow_above_the_critical_load(self):
        p, s, st = self.runs[self.HIGH]
        self.assertEqual(p.returncode, 0, p.stderr)
        r = s["results"]
        strain = r["elastic_strain"]
        # Far beyond the elastic estimate and its dynamic overshoot 1 - 2 P/E.
        self.assertLess(st["delta_h"].min(), 1 - 2.5 * strain)
        self.assertLess(st["delta_h"].min(), 0.5)
        self.assertTrue(r["stopped_by_stroke"])
        # The slab spreads sideways as it flows.
        self.assertGreater(st["delta_w"].max(), 1.5)
        print("\n  P = %g Pa: P/E = %.4f, delta_h min %.3f (elastic %.3f), delta_w max %.2f" %
              (self.HIGH, strain, st["delta_h"].min(), 1 - strain, st["delta_w"].max()))

    def test_density_maps_and_histograms(self):
        import h5py
        p, s, _ = self.runs[self.LOW]
        out = os.path.join(self.dir.name, "slab_%g" % self.LOW)
        with h5py.File(os.path.join(out, "results.h5"), "r") as f:
            snap = f["density_snapshots/mean_relative_density"][()]
            hist = f["density_histograms/fraction"][()]
            k = f["density_histograms/snapshot"][()]
        # Three snapshots; the histogram of each sums to 1; the first (ideal lattice)
        # has a mean relative density near 1 (surface particles lower it).
        self.assertEqual(len(snap), 3)
        for i in range(3):
            self.assertAlmostEqual(hist[k == i].sum(), 1.0, places=9)
        self.assertGreater(snap[0], 0.75)
        self.assertLess(snap[0], 1.05)


class Ordering(unittest.TestCase):
    """256 random particles, 2 us at low temperature; structure factor on the Bragg ring."""

    def peaks(self, lattice):
        with tempfile.TemporaryDirectory() as d:
            p, s, _ = run(d, "order", "mlp_ordering",
                          {"Lattice": lattice, "Damping": 0.05, "Thermal energy": 1e-7,
                           "Time step": 3e-10, "Statistics interval": 100},
                          ("Ordering", {"Particles": 256, "Region enlargement": 1.2}),
                          "set End time = 2e-6")
            self.assertEqual(p.returncode, 0, p.stderr)
            import h5py
            with h5py.File(os.path.join(d, "order", "results.h5"), "r") as f:
                qx, qy, S = (f["structure_factor/" + k][()] for k in ("qx", "qy", "S"))
        qb = s["results"]["bragg_wave_number"]
        q = np.hypot(qx, qy) / qb
        ring = (q > 0.85) & (q < 1.15)
        theta = np.degrees(np.arctan2(qy[ring], qx[ring])) % 360
        # Angular profile in 5-degree bins centred on multiples of 5 degrees; the
        # directions in decreasing strength, each at least 20 degrees from the ones before.
        prof, _ = np.histogram((theta + 2.5) % 360, bins=72, range=(0, 360), weights=S[ring])
        centres = 5.0 * np.arange(72)
        order = np.argsort(prof)[::-1]
        found = []
        for i in order:
            if all(min(abs(centres[i] - c), 360 - abs(centres[i] - c)) > 20 for c in found):
                found.append(centres[i])
        return s["results"], found, prof

    def check(self, lattice, n, offset):
        r, found, prof = self.peaks(lattice)
        top = found[:n]
        peaks = sorted(top)
        gaps = np.diff(peaks + [peaks[0] + 360])
        print("\n  %s: peaks at %s deg, harmonic_%d %.3f, other %.3f" %
              (lattice, [round(a, 1) for a in peaks], n, r["harmonic_%d" % n],
               r["harmonic_%d" % (10 - n)]))
        for a in peaks:
            d = (a - offset) % (360.0 / n)
            self.assertLess(min(d, 360.0 / n - d), 7.5)
        for g in gaps:
            self.assertAlmostEqual(g, 360.0 / n, delta=10)
        # The n peaks dominate the ring: the next direction is much weaker.
        weakest = min(prof[int(round(a / 5)) % 72] for a in top)
        if len(found) > n:
            self.assertLess(prof[int(round(found[n] / 5)) % 72], 0.3 * weakest)
        self.assertGreater(r["harmonic_%d" % n], 0.6)
        self.assertLess(r["harmonic_%d" % (10 - n)], 0.1)

    def test_hexagonal_order_has_six_peaks_60_degrees_apart(self):
        self.check("hexagonal", 6, 30.0)

    def test_square_order_has_four_peaks_90_degrees_apart(self):
        self.check("square", 4, 0.0)


class Beams(unittest.TestCase):
    """cases/mlp/beams.prm (two beams of 32 x 12 rubbed, 1 us, about 3 s)."""

    def test_contact_over_bulk_from_the_profile_with_its_standard_error(self):
        with tempfile.TemporaryDirectory() as d:
            case = os.path.join(os.path.dirname(__file__), "..", "..", "cases", "mlp", "beams.prm")
            out = os.path.join(d, "beams")
            p = subprocess.run([TRIBO, "run", case, "--output", out, "--quiet", "--set", "Output/Plots=false"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(os.path.join(out, "summary.json")) as f:
                r = json.load(f)["results"]
            with open(os.path.join(out, "profiles.csv")) as f:
                rows = list(csv.DictReader(f))
            prof = {k: np.array([float(x[k]) for x in rows]) for k in rows[0]}
        # The window means: layers within 1.5 row spacings of the contact and of each beam's
        # mid-plane (12 rows of sqrt(3)/2 r0 per beam), weighted by their samples.
        h_row = prof["y"][1] - prof["y"][0]  # Layer thickness = 1 row spacing
        half_beam = 0.5 * 12 * h_row

        def window(column, y0):
            sel = np.abs(prof["y_from_contact"] - y0) <= 1.5 * h_row + 1e-12 * h_row
            n = prof["n_samples"][sel]
            return (prof[column][sel] * n).sum() / n.sum()

        for kind in ("net", "bond"):
            column = "f_return_" + kind
            bulk = 0.5 * (window(column, -half_beam) + window(column, half_beam))
            ratio = window(column, 0.0) / bulk
            self.assertAlmostEqual(r["contact_over_bulk_" + kind], ratio, delta=1e-9 * ratio)
            se = r["contact_over_bulk_%s_stderr" % kind]
            print("\n  contact / bulk |F_return| (%s): %.3f +/- %.3f" % (kind, ratio, se))
            self.assertGreater(se, 0)
            self.assertLess(se, 0.5 * ratio)


class Control(unittest.TestCase):
    def test_interrupted_run_keeps_outputs(self):
        self.check_interrupted(signal.SIGINT)

    def test_terminated_run_keeps_outputs(self):
        self.check_interrupted(signal.SIGTERM)

    def check_interrupted(self, sig):
        with tempfile.TemporaryDirectory() as d:
            case = os.path.join(d, "long.prm")
            write_case(case, "mlp_compression", SLAB, ("Compression", {"Pressure": 1e8}),
                       "set End time = 1e-3")
            out = os.path.join(d, "long")
            proc = subprocess.Popen([TRIBO, "run", case, "--output", out, "--quiet"],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            time.sleep(2.0)
            proc.send_signal(sig)
            proc.communicate(timeout=60)
            self.assertEqual(proc.returncode, 128 + sig)
            with open(os.path.join(out, "summary.json")) as f:
                s = json.load(f)
            self.assertEqual(s["status"], "interrupted")
            self.assertEqual(s["signal"], sig)
            self.assertGreater(s["steps"], 0)
            self.assertLess(s["steps"], s["steps_planned"])
            st = statistics(out)
            self.assertEqual(int(st["step"][-1]), s["steps"])
            self.assertAlmostEqual(st["time"][-1], s["steps"] * 2e-10, delta=1e-15)
            # The slab was being compressed: widths are physical, below 1.
            self.assertLess(st["delta_h"][-1], 1.0)
            self.assertGreater(st["delta_h"][-1], 0.85)
            self.assertTrue(os.path.exists(os.path.join(out, "fields", "particles.pvd")))

    def test_run_error_fails_and_keeps_outputs(self):
        # 3e9 Pa (P/E = 2.4) at the largest accepted step: the slab is crushed and flies
        # apart; the run ends as failed (exit 1) with the reason and the rows so far.
        with tempfile.TemporaryDirectory() as d:
            p, s, st = run(d, "crush", "mlp_compression",
                           dict(SLAB, **{"Time step": 9e-10}),
                           ("Compression", {"Pressure": 3e9, "Density maps": 0}),
                           "set End time = 3e-6")
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertEqual(s["status"], "failed")
            self.assertIn("flew apart; lower MLP/Time step", s["error"])
            self.assertEqual(int(st["step"][-1]), s["steps"])
            self.assertLess(s["steps"], s["steps_planned"])

    def test_youngs_modulus_and_poisson_ratio_set_the_model(self):
        # The (E, nu) mapping wins over Pair stiffness and Return force amplitude: the
        # linear theory of the resulting lattice gives back E; the wave moves at its c_L.
        with tempfile.TemporaryDirectory() as d:
            p, s, _ = run(d, "mapped", "mlp_compression",
                          {"Young's modulus": 2e9, "Poisson ratio": 0.2, "Pair stiffness": 5e9,
                           "Return force amplitude": 0, "Damping": 0, "Thermal energy": 0,
                           "Time step": 2e-10},
                          ("Compression", {"Columns": 80, "Rows": 40, "Pressure": 1e6,
                                           "Density maps": 0, "Second probe": 0.45}),
                          "set End time = 1e-7")
            self.assertEqual(p.returncode, 0, p.stderr)
            r = s["results"]
            self.assertAlmostEqual(r["youngs_modulus_theory"] / 2e9, 1.0, places=9)
            # pure-strain mapping: k_c = (2/sqrt(3))(lambda + mu), lambda + mu = E/(2(1 - nu))
            self.assertAlmostEqual(s["pair_stiffness"], 2 / math.sqrt(3) * 2e9 / (2 * 0.8), delta=1)
            self.assertGreater(s["return_force_amplitude"], 0)
            print("\n  mapped: k_c %.4g Pa, f0 %.4g N/m, E %.4g Pa, c %.2f / c_L %.2f m/s" %
                  (s["pair_stiffness"], s["return_force_amplitude"], r["youngs_modulus_theory"],
                   r["wave_speed"], r["longitudinal_speed_theory"]))
            self.assertAlmostEqual(r["wave_speed_over_theory"], 1.0, delta=0.03)

    def test_unstable_time_step_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            case = os.path.join(d, "bad.prm")
            with open(case, "w") as f:
                f.write("subsection Simulation\n  set Scene = mlp_compression\nend\n"
                        "subsection MLP\n  set Time step = 2e-9\nend\n")
            p = subprocess.run([TRIBO, "run", case, "--output", os.path.join(d, "bad"), "--quiet"],
                               cwd=d, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               universal_newlines=True, timeout=60)
            self.assertEqual(p.returncode, 2)
            self.assertEqual(
                p.stderr.strip(),
                "error: %s:5: entry 'MLP/Time step' = '2e-9': MLP Langevin: time step 2e-09 s "
                "exceeds the stable limit 9.80166e-10 s (0.5 x 2/omega_max, omega_max = "
                "1.02024e+09 rad/s from the stiffest bond k = 1e+09 N/m^2 and mass m = "
                "6.755e-09 kg/m); use a time step of at most 9.80166e-10 s, e.g. 4.90083e-10 s" % case)
            self.assertFalse(os.path.exists(os.path.join(d, "bad")), "refused before writing anything")

    def test_bad_interface_offset_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            case = os.path.join(d, "bad.prm")
            write_case(case, "mlp_beams", {}, ("Beams", {"Interface offset": 1.5}))
            with open(case) as f:
                line = 1 + [l.strip() for l in f].index("set Interface offset = 1.5")
            p = subprocess.run([TRIBO, "run", case, "--output", os.path.join(d, "bad"), "--quiet"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               universal_newlines=True, timeout=60)
            self.assertEqual(p.returncode, 2)
            self.assertEqual(p.stderr.strip(),
                             "error: %s:%d: entry 'MLP beams/Interface offset' = '1.5': expected a "
                             "fraction of r0 in [0, 1)" % (case, line))
            self.assertFalse(os.path.exists(os.path.join(d, "bad")), "refused before writing anything")

if __name__ == "__main__":
    if len(sys.argv) < 2 or not os.path.isfile(sys.argv[1]):
        sys.stderr.write("usage: %s /path/to/tribo [unittest options]\n" % sys.argv[0])
        sys.exit(2)
    TRIBO = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0]] + sys.argv[2:], verbosity=2)
