"""Bad input: every kind gives exit code 2, one line on stderr that names the
file and line (or the entry, or the option) and what was expected, no stack
trace, and no output directory. Good input passes `tribo check`.

Usage: /usr/bin/python3 test_bad_input.py /path/to/tribo
"""

import os
import re
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tribo_cli  # noqa: E402
from tribo_cli import TempDirTestCase, run, write_prm  # noqa: E402

#: A small valid collision case.
GOOD = {
    "Simulation": {"Scene": "collision", "End time": "1e-9"},
    "Contact law": {"Law": "ELAS"},
    "Collision": {"Diameter": "1.2e-6", "Density": "7800"},
}


def case(changes):
    """GOOD with {"Subsection/Entry": value} changes (value None removes the entry)."""
    sections = {s: dict(e) for s, e in GOOD.items()}
    for path, value in changes.items():
        section, entry = path.split("/")
        sections.setdefault(section, {})
        if value is None:
            sections[section].pop(entry, None)
        else:
            sections[section][entry] = value
    return sections


class BadInputTestCase(TempDirTestCase):
    """Helpers: run tribo on bad input and check the whole contract."""

    def run_bad(self, args, env=None):
        """Run `tribo ARGS` in self.tmp (environment @p env); check exit 2, one line on
        stderr, nothing on stdout, no stack trace, nothing created. Returns the message."""
        before = sorted(os.listdir(self.tmp))
        r = run(args, cwd=self.tmp, env=env)
        msg = r.stderr.strip()
        self.assertEqual(r.returncode, 2, "tribo %s: exit %d, stderr %r" % (" ".join(args), r.returncode, r.stderr))
        self.assertEqual(r.stdout, "", "nothing on stdout for bad input")
        self.assertEqual(len(msg.splitlines()), 1, "a one-line message, got %r" % r.stderr)
        self.assertTrue(msg.startswith("error: "), msg)
        for marker in tribo_cli.STACK_TRACE_MARKERS:
            self.assertNotIn(marker, r.stderr)
        self.assertEqual(sorted(os.listdir(self.tmp)), before,
                         "bad input must not create files or an output directory")
        return msg

    def run_bad_case(self, sections, preamble=""):
        """Write case.prm, run `tribo run case.prm --output out --quiet`; returns
        (message, {entry path: line})."""
        where = write_prm(os.path.join(self.tmp, "case.prm"), sections, preamble)
        msg = self.run_bad(["run", "case.prm", "--output", "out", "--quiet"])
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "out")))
        return msg, where

    def assert_at_line(self, msg, line, filename="case.prm"):
        """The message points at FILE:LINE (tribo's form) or deal.II's 'Line <N> of file <FILE'."""
        f = re.escape(filename)
        pattern = r"(?:(?<![\w/.]){f}:{l}\b|Line <{l}> of file <{f}\b)".format(f=f, l=line)
        self.assertRegex(msg, pattern, "message should point at %s line %d" % (filename, line))

    def assert_parts(self, msg, *parts):
        for p in parts:
            self.assertIn(p, msg)


class MisspeltNames(BadInputTestCase):
    def test_misspelt_entry(self):
        msg, where = self.run_bad_case(case({"Simulation/Time stepp": "1e-9"}))
        self.assert_at_line(msg, where["Simulation/Time stepp"])
        self.assert_parts(msg, "case.prm", "<Time stepp>", "No entry", "declared",
                          "(did you mean 'Simulation/Time step'?)")

    def test_a_study_file_given_as_a_case_says_how_to_run_it(self):
        with open(os.path.join(self.tmp, "study.prm"), "w") as f:
            f.write("subsection Study\n  set Base case = case.prm\nend\n")
        msg = self.run_bad(["check", "study.prm"])
        self.assert_parts(msg, "study.prm", "no such subsection to be entered: Study",
                          "(a study file: run it with `tribo study` or `tribo tradeoff`)")

    def test_misspelt_subsection(self):
        sections = {"Simulaton": {"Time step": "1e-9"}}
        sections.update(GOOD)
        msg, _ = self.run_bad_case(sections)
        self.assert_at_line(msg, 1)
        self.assert_parts(msg, "case.prm", "Simulaton", "no such subsection")

    def test_line_that_is_no_statement(self):
        path = os.path.join(self.tmp, "case.prm")
        write_prm(path, GOOD)
        with open(path) as f:
            lines = f.read().splitlines()
        lines.insert(1, "  sett Time step = 1e-9")
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        msg = self.run_bad(["run", "case.prm", "--output", "out", "--quiet"])
        self.assert_at_line(msg, 2)
        self.assert_parts(msg, "sett Time step = 1e-9", "could not be parsed", "'set'")

    def test_unbalanced_subsection(self):
        path = os.path.join(self.tmp, "case.prm")
        with open(path, "w") as f:
            f.write("subsection Simulation\n  set Time step = 1e-9\n")
        msg = self.run_bad(["run", "case.prm", "--output", "out", "--quiet"])
        self.assert_parts(msg, "case.prm", "'subsection' and 'end'")


class WrongTypes(BadInputTestCase):
    def test_text_for_a_number(self):
        msg, where = self.run_bad_case(case({"Collision/Density": "heavy"}))
        self.assert_at_line(msg, where["Collision/Density"])
        self.assert_parts(msg, "Density", "heavy", "Double")

    def test_number_with_a_unit(self):
        msg, where = self.run_bad_case(case({"Collision/Diameter": "1.2 um"}))
        self.assert_at_line(msg, where["Collision/Diameter"])
        self.assert_parts(msg, "Diameter", "1.2 um", "Double")

    def test_unknown_selection(self):
        msg, where = self.run_bad_case(case({"Simulation/Scene": "sliding"}))
        self.assert_at_line(msg, where["Simulation/Scene"])
        self.assert_parts(msg, "Scene", "sliding", "collision|shear")

    def test_removed_scene(self):
        """The compaction scene is gone (a compaction is a shear run with Shear start >= End time)."""
        msg, where = self.run_bad_case(case({"Simulation/Scene": "compaction"}))
        self.assert_at_line(msg, where["Simulation/Scene"])
        self.assert_parts(msg, "Scene", "compaction", "collision|shear")

    def test_removed_subsection(self):
        sections = {"Simulation": {"Scene": "shear"}, "Compaction": {"Number of discs": "60"}}
        msg, _ = self.run_bad_case(sections)
        self.assert_at_line(msg, 5)  # line 5: "subsection Compaction"
        self.assert_parts(msg, "case.prm", "Compaction", "no such subsection")

    def test_not_a_bool(self):
        msg, where = self.run_bad_case(case({"Collision/Stop when separated": "maybe"}))
        self.assert_at_line(msg, where["Collision/Stop when separated"])
        self.assert_parts(msg, "Stop when separated", "maybe", "Bool")

    def test_plots_not_a_bool(self):
        msg, where = self.run_bad_case(case({"Output/Plots": "yes please"}))
        self.assert_at_line(msg, where["Output/Plots"])
        self.assert_parts(msg, "Plots", "yes please", "Bool")


class MeaninglessValues(BadInputTestCase):
    """Values of the right type but out of range or physically meaningless."""

    def check_entry(self, path, value, expected, sections=None):
        """The tribo form: FILE:LINE: entry 'PATH' = 'VALUE': expected EXPECTED."""
        msg, where = self.run_bad_case(sections or case({path: value}))
        self.assert_at_line(msg, where[path])
        self.assert_parts(msg, "entry '%s' = '%s'" % (path, value), "expected " + expected)

    def test_negative_density(self):
        self.check_entry("Collision/Density", "-7800", "a positive density in kg/m^3")

    def test_zero_time_step(self):
        self.check_entry("Simulation/Time step", "0", "a positive time step in s")

    def test_negative_end_time(self):
        self.check_entry("Simulation/End time", "-1e-6", "a positive end time in s")

    def test_theta_below_one_half(self):
        msg, where = self.run_bad_case(case({"Simulation/Theta": "0.3"}))
        self.assert_at_line(msg, where["Simulation/Theta"])
        self.assert_parts(msg, "Theta", "0.3", "0.5...1")

    def test_theta_above_one(self):
        msg, where = self.run_bad_case(case({"Simulation/Theta": "1.2"}))
        self.assert_at_line(msg, where["Simulation/Theta"])
        self.assert_parts(msg, "Theta", "1.2", "0.5...1")

    def test_empty_sample(self):
        sections = {"Simulation": {"Scene": "shear"}, "Shear cell": {"Number of discs": "0"}}
        msg, where = self.run_bad_case(sections)
        self.assert_at_line(msg, where["Shear cell/Number of discs"])
        self.assert_parts(msg, "Number of discs", "0", "Integer range 1...")

    def shear_entry(self, entry, value, expected):
        """A small shear case with 'Shear cell/ENTRY' = VALUE: the tribo form of the message."""
        sections = {"Simulation": {"Scene": "shear"},
                    "Shear cell": {"Number of discs": "60", "Length": "1.2e-5", "Wall discs": "0"}}
        sections["Shear cell"][entry] = value
        self.check_entry("Shear cell/" + entry, value, expected, sections)

    def test_negative_shear_start(self):
        self.shear_entry("Shear start", "-1e-7", "a time >= 0 in s")

    def test_negative_ramp_time(self):
        self.shear_entry("Pressure ramp time", "-1e-7", "a time >= 0 in s")

    def test_zero_pressure(self):
        self.shear_entry("Pressure", "0", "a positive pressure in Pa")

    def test_too_many_wall_discs(self):
        # d (1 - s) = 0.96e-6 m: at most 12 discs fit along 1.2e-5 m.
        self.shear_entry("Wall discs", "13", "at most 12 discs")

    def test_wall_disc_too_large(self):
        # L/8 = 1.5e-6 m for L = 1.2e-5 m.
        self.shear_entry("Wall disc diameter", "2e-6",
                         "a diameter of at most L/8 = 1.5e-06 m (a wall of at least 8 discs), or 0")

    def test_wall_discs_of_a_given_diameter_must_fit(self):
        # 1.2e-6 m discs: 10 fit along 1.2e-5 m, 11 do not.
        sections = {"Simulation": {"Scene": "shear"},
                    "Shear cell": {"Number of discs": "60", "Length": "1.2e-5", "Wall discs": "11",
                                   "Wall disc diameter": "1.2e-6"}}
        self.check_entry("Shear cell/Wall discs", "11", "at most 10 discs", sections)

    def test_negative_cohesion(self):
        self.check_entry("Contact law/Cohesion", "-1", "a cohesion >= 0 in N/m")

    def test_cohesion_without_range(self):
        sections = case({"Contact law/Cohesion": "0.5", "Contact law/Cohesion range": "0"})
        self.check_entry("Contact law/Cohesion range", "0",
                         "a positive range in m, since Contact law/Cohesion > 0", sections)

    def test_cohesion_with_default_range(self):
        """The range left at its default: the message says so instead of a line."""
        msg, _ = self.run_bad_case(case({"Contact law/Cohesion": "0.5"}))
        self.assert_parts(msg, "case.prm (default)", "entry 'Contact law/Cohesion range' = '0'",
                          "expected a positive range in m, since Contact law/Cohesion > 0")

    def test_zero_relaxation(self):
        self.check_entry("Solver/Relaxation", "0", "a relaxation in (0, 1]")

    def test_residual_target_out_of_range(self):
        self.check_entry("Solver/Residual target", "0", "a relative residual in (0, 1)")
        self.check_entry("Solver/Residual target", "2", "a relative residual in (0, 1)")

    def test_negative_gap_target(self):
        self.check_entry("Solver/Gap target", "-0.01", "a fraction >= 0 of the smallest radius")

    def test_unknown_solver_method(self):
        msg, where = self.run_bad_case(case({"Solver/Method": "cg"}))
        self.assert_at_line(msg, where["Solver/Method"])
        self.assert_parts(msg, "Method", "cg", "nlgs|active-set|mprgp|interior-point")

    def test_bands_need_the_fixed_order(self):
        sections = case({"Solver/Threads": "2", "Solver/Contact order": "random"})
        self.check_entry("Solver/Threads", "2",
                         "1 with Solver/Contact order = random (bands solved at once need the fixed order)",
                         sections)

    def test_zero_impact_velocity(self):
        self.check_entry("Collision/Impact velocity", "0", "a non-zero velocity in m/s")

    def test_period_too_short(self):
        # 8 largest diameters: 8 x 1.2e-6 x 1.2 = 1.152e-5 m.
        sections = {"Simulation": {"Scene": "shear"},
                    "Shear cell": {"Number of discs": "10", "Length": "1.1e-5"}}
        msg, where = self.run_bad_case(sections)
        self.assert_at_line(msg, where["Shear cell/Length"])
        self.assert_parts(msg, "entry 'Shear cell/Length' = '1.1e-5'",
                          "expected a length of at least 8 largest diameters (1.152e-05 m)")

    def test_default_shear_case_is_valid(self):
        """The limits above are the only ones hit: the same case with a long enough
        period passes `tribo check`."""
        write_prm(os.path.join(self.tmp, "case.prm"),
                  {"Simulation": {"Scene": "shear"},
                   "Shear cell": {"Number of discs": "10", "Length": "1.2e-5", "Wall discs": "12"}})
        r = run(["check", "case.prm"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), "case.prm: OK (scene shear)")

    def test_check_gives_the_same_message(self):
        write_prm(os.path.join(self.tmp, "case.prm"), case({"Collision/Density": "-1"}))
        msg_run = self.run_bad(["run", "case.prm", "--output", "out", "--quiet"])
        msg_check = self.run_bad(["check", "case.prm"])
        self.assertEqual(msg_run, msg_check)


class Files(BadInputTestCase):
    def test_missing_file(self):
        msg = self.run_bad(["run", "missing.prm", "--output", "out"])
        self.assert_parts(msg, "missing.prm", "cannot open the parameter file")

    @unittest.skipIf(os.geteuid() == 0,
                     "running as root: root reads a file whatever its mode, so chmod 000 "
                     "cannot make it unreadable (test_directory_instead_of_file covers "
                     "an unreadable path)")
    def test_unreadable_file(self):
        path = os.path.join(self.tmp, "case.prm")
        write_prm(path, GOOD)
        os.chmod(path, 0)
        msg = self.run_bad(["run", "case.prm", "--output", "out"])
        self.assert_parts(msg, "case.prm", "cannot open the parameter file")

    def test_directory_instead_of_file(self):
        os.mkdir(os.path.join(self.tmp, "case.prm"))
        msg = self.run_bad(["run", "case.prm", "--output", "out", "--quiet"])
        self.assert_parts(msg, "case.prm")


class CommandLine(BadInputTestCase):
    def setUp(self):
        super().setUp()
        write_prm(os.path.join(self.tmp, "good.prm"), GOOD)

    def run_set(self, assignment):
        return self.run_bad(["run", "good.prm", "--set", assignment, "--output", "out", "--quiet"])

    def test_set_unknown_entry(self):
        msg = self.run_set("Simulation/Foo=1")
        self.assertEqual(msg, "error: --set 'Simulation/Foo=1': there is no entry 'Simulation/Foo' "
                         "(see `tribo params`)")

    def test_set_misspelt_entry_names_the_nearest(self):
        msg = self.run_set("Shear cell/Sliding speed=2")
        self.assertEqual(msg, "error: --set 'Shear cell/Sliding speed=2': there is no entry 'Shear "
                         "cell/Sliding speed' (did you mean 'Shear cell/Sliding velocity'?) (see `tribo params`)")

    def test_set_unknown_subsection(self):
        msg = self.run_set("Simulatio/Time step=1e-9")
        self.assert_parts(msg, "--set 'Simulatio/Time step=1e-9'", "no subsection 'Simulatio'")

    def test_set_without_equals(self):
        msg = self.run_set("Simulation/Time step")
        self.assert_parts(msg, "--set 'Simulation/Time step'", 'expected "Subsection/Entry=value"')

    def test_set_without_entry(self):
        msg = self.run_set("=3")
        self.assert_parts(msg, "--set '=3'")

    def test_set_wrong_type(self):
        msg = self.run_set("Simulation/Time step=abc")
        self.assert_parts(msg, "--set 'Simulation/Time step=abc'", "<abc>", "Double")

    def test_set_out_of_pattern(self):
        msg = self.run_set("Simulation/Theta=0.3")
        self.assert_parts(msg, "--set 'Simulation/Theta=0.3'", "<0.3>", "0.5...1")

    def test_set_meaningless_value(self):
        msg = self.run_set("Simulation/Time step=0")
        self.assert_parts(msg, "--set: entry 'Simulation/Time step' = '0'", "expected a positive time step in s")

    def test_set_needs_a_value(self):
        msg = self.run_bad(["run", "good.prm", "--set"])
        self.assert_parts(msg, "--set needs a value")

    def test_unknown_option(self):
        msg = self.run_bad(["run", "good.prm", "--bogus"])
        self.assert_parts(msg, "unknown option '--bogus'", "tribo --help")

    def test_unknown_command(self):
        msg = self.run_bad(["frobnicate", "good.prm"])
        self.assert_parts(msg, "unknown command 'frobnicate'", "tribo --help")

    def test_run_without_case(self):
        msg = self.run_bad(["run", "--quiet"])
        self.assert_parts(msg, "'tribo run' needs a case file")

    def test_two_case_files(self):
        msg = self.run_bad(["run", "good.prm", "other.prm"])
        self.assert_parts(msg, "more than one case file", "'good.prm'", "'other.prm'")


class GoodInput(TempDirTestCase):
    def test_check_good_case(self):
        write_prm(os.path.join(self.tmp, "good.prm"), GOOD)
        r = run(["check", "good.prm"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), "good.prm: OK (scene collision)")
        self.assertEqual(r.stderr, "")
        self.assertEqual(sorted(os.listdir(self.tmp)), ["good.prm"], "check writes nothing")

    def test_params_parse_back(self):
        r = run(["params"], cwd=self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("subsection Simulation", r.stdout)
        with open(os.path.join(self.tmp, "all.prm"), "w") as f:
            f.write(r.stdout)
        for extra in ([], ["--set", "Simulation/Scene=collision"]):
            c = run(["check", "all.prm"] + extra, cwd=self.tmp)
            self.assertEqual(c.returncode, 0, c.stderr)
            self.assertIn("all.prm: OK", c.stdout)


if __name__ == "__main__":
    tribo_cli.main()
