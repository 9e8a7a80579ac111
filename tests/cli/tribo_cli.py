"""Helpers shared by the command-line tests (tests/cli/test_*.py).

Every test script is run by ctest as

    /usr/bin/python3 tests/cli/test_NAME.py /path/to/tribo [unittest options]

and calls tribo_cli.main(), which takes the tribo executable off the command
line and runs unittest (exit status non-zero on any failure).

Readers here are deliberately independent of tribo's own code: CSV through
the csv module, JSON through json, HDF5 through h5py, PNG through matplotlib's
image reader, VTU through VTK and through a small XML/base64/zlib decoder (used
to check a file's structure before VTK sees it, since VTK may crash on
malformed files).
"""

import base64
import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import xml.etree.ElementTree as ET
import zlib

import numpy as np

#: Absolute path of the tribo executable (set by main()).
TRIBO = None

#: The repository's docs/outputs.md, relative to this file.
OUTPUTS_MD = os.path.normpath(
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "outputs.md"))

#: Columns every statistics.csv starts with, in this order (docs/outputs.md).
COMMON_COLUMNS = [
    "time", "step", "n_contacts", "n_active_contacts", "solver_iterations", "solver_residual",
    "solver_converged", "law_residual", "gap_violation", "epsilon", "max_overlap", "kinetic_energy", "power_external",
    "power_free", "power_contacts"]
#: Columns added by each scene, in this order.
SCENE_COLUMNS = {
    "collision": ["gap", "relative_normal_velocity", "normal_force", "energy_change"],
    "shear": ["mu", "normal_force", "lower_wall_normal_force", "upper_wall_y", "upper_wall_vy",
              "gap", "power_lower_wall", "power_upper_wall", "power_dissipated",
              "kinetic_energy_third_body", "kinetic_energy_upper_wall", "solid_fraction"],
}
#: Columns of profiles.csv (and datasets of the HDF5 group "profiles"), in this order.
PROFILE_QUANTITIES = ["vx", "solid_fraction", "sigma_xx", "sigma_yy", "sigma_xy", "sigma_yx", "n_discs",
                      "power_dissipated", "granular_temperature"]
PROFILE_COLUMNS = ["layer", "y", "y_over_h"] + PROFILE_QUANTITIES + ["n_samples"] + \
    [q + "_stderr" for q in PROFILE_QUANTITIES]
#: PNG plots of a shear run with Output/Plots = true (scripts/plot_run.py).
PLOTS = ["mu.png", "power.png", "profiles.png"]

#: Text that must never reach a user: deal.II's exception banner and stack trace.
STACK_TRACE_MARKERS = ["An error occurred in line", "Stacktrace", "--------------------------------------------------------"]


def main():
    """Run the unittest tests of the calling module with tribo from argv[1]."""
    global TRIBO
    if len(sys.argv) < 2 or not os.path.isfile(sys.argv[1]):
        sys.stderr.write("usage: %s /path/to/tribo [unittest options]\n" % sys.argv[0])
        sys.exit(2)
    TRIBO = os.path.abspath(sys.argv[1])
    unittest.main(module="__main__", argv=[sys.argv[0]] + sys.argv[2:], verbosity=2)


def run(args, cwd, timeout=120, env=None):
    """Run tribo with @p args in directory @p cwd (and environment @p env, default ours);
    returns the CompletedProcess (text)."""
    return subprocess.run([TRIBO] + list(args), cwd=cwd, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True, timeout=timeout, env=env)


def write_prm(path, sections, preamble=""):
    """Write a case file from {subsection: {entry: value}} (dicts keep their order).

    Returns {"Subsection/Entry": line number (1-based)} of every "set" written.
    """
    lines = preamble.splitlines() if preamble else []
    where = {}
    for section, entries in sections.items():
        lines.append("subsection %s" % section)
        for entry, value in entries.items():
            lines.append("  set %s = %s" % (entry, value))
            where["%s/%s" % (section, entry)] = len(lines)
        lines.append("end")
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return where


def read_csv(path):
    """statistics.csv (or a scene table such as profiles.csv) as
    (header list, {column: float array}); a file with a header only gives empty arrays."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
    data = data.reshape(-1, len(header))
    return header, {name: data[:, i] for i, name in enumerate(header)}


def read_json(path):
    with open(path) as f:
        return json.load(f)


def read_png(testcase, path):
    """Check that @p path is a PNG file (signature) and read it with matplotlib's
    image reader; returns the image array (rows x columns [x channels])."""
    with open(path, "rb") as f:
        testcase.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", "%s: not a PNG file" % path)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image
    return matplotlib.image.imread(path)


def read_pvd(path):
    """A .pvd collection as a list of (time, file name)."""
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def tmp_files(directory):
    """Every *.tmp file below @p directory (relative paths)."""
    found = []
    for base, _, files in os.walk(directory):
        found += [os.path.relpath(os.path.join(base, f), directory) for f in files if f.endswith(".tmp")]
    return found


# ---------------------------------------------------------------------------
# VTU files: structure check and decoding without VTK.

_VTK_TYPES = {"Float32": "<f4", "Float64": "<f8", "Int8": "<i1", "UInt8": "<u1",
              "Int16": "<i2", "UInt16": "<u2", "Int32": "<i4", "UInt32": "<u4",
              "Int64": "<i8", "UInt64": "<u8"}


def _decode_array(element, compressed, header_type):
    dtype = np.dtype(_VTK_TYPES[element.get("type")])
    text = "".join((element.text or "").split())
    fmt = element.get("format", "ascii")
    if fmt == "ascii":
        return np.array((element.text or "").split(), dtype=float).astype(dtype)
    if fmt != "binary":
        raise ValueError("unsupported DataArray format %r" % fmt)
    if not text:
        return np.zeros(0, dtype=dtype)
    word = np.dtype("<u4" if header_type == "UInt32" else "<u8")
    if not compressed:
        raw = base64.b64decode(text)
        size = int(np.frombuffer(raw[:word.itemsize], dtype=word)[0])
        return np.frombuffer(raw[word.itemsize:word.itemsize + size], dtype=dtype).copy()
    # Compressed: base64(header) + base64(blocks), header = [n, block, last, sizes...].
    first = base64.b64decode(text[:12])[:word.itemsize]
    n_blocks = int(np.frombuffer(first, dtype=word)[0])
    header_bytes = (3 + n_blocks) * word.itemsize
    header_chars = 4 * ((header_bytes + 2) // 3)
    header = np.frombuffer(base64.b64decode(text[:header_chars])[:header_bytes], dtype=word)
    sizes = [int(s) for s in header[3:]]
    blob = base64.b64decode(text[header_chars:])
    out, pos = b"", 0
    for s in sizes:
        out += zlib.decompress(blob[pos:pos + s])
        pos += s
    return np.frombuffer(out, dtype=dtype).copy()


def decode_vtu(path):
    """Decode an UnstructuredGrid VTU (one piece) without VTK.

    Returns a dict: n_points, n_cells, points (n x 3 or None if no <Points>),
    connectivity, offsets, types (arrays or None if absent), point_data
    {name: (n x components) array} and problems, a list of what makes the
    file malformed for VTK (empty when it is well formed).
    """
    root = ET.parse(path).getroot()
    compressed = root.get("compressor") is not None
    header_type = root.get("header_type", "UInt32")
    piece = root.find("UnstructuredGrid/Piece")
    n_points = int(piece.get("NumberOfPoints"))
    n_cells = int(piece.get("NumberOfCells"))
    out = {"n_points": n_points, "n_cells": n_cells, "points": None, "connectivity": None,
           "offsets": None, "types": None, "point_data": {}, "problems": []}
    problems = out["problems"]

    points = piece.find("Points/DataArray")
    if points is None:
        problems.append("no <Points> element (NumberOfPoints=%d)" % n_points)
    else:
        p = _decode_array(points, compressed, header_type)
        if p.size != 3 * n_points:
            problems.append("Points holds %d values for %d points" % (p.size, n_points))
        else:
            out["points"] = p.reshape(n_points, 3)

    cells = {a.get("Name"): a for a in piece.findall("Cells/DataArray")}
    for name in ("connectivity", "offsets", "types"):
        if name not in cells:
            problems.append("no Cells/%s array" % name)
            continue
        out[name] = _decode_array(cells[name], compressed, header_type)
    for name in ("offsets", "types"):
        if out[name] is not None and out[name].size != n_cells:
            problems.append("Cells/%s has %d entries for %d cells" % (name, out[name].size, n_cells))
    if out["offsets"] is not None and out["connectivity"] is not None and out["offsets"].size:
        if out["offsets"][-1] != out["connectivity"].size:
            problems.append("last offset %d != %d connectivity entries"
                            % (out["offsets"][-1], out["connectivity"].size))

    for a in piece.findall("PointData/DataArray"):
        values = _decode_array(a, compressed, header_type)
        ncomp = int(a.get("NumberOfComponents", "1"))
        if values.size != ncomp * n_points:
            problems.append("PointData %s holds %d values for %d points x %d components"
                            % (a.get("Name"), values.size, n_points, ncomp))
            continue
        out["point_data"][a.get("Name")] = values.reshape(n_points, ncomp)
    return out


def pvtu_pieces(path):
    """The piece files a .pvtu record names, as paths next to it."""
    root = ET.parse(path).getroot()
    return [os.path.join(os.path.dirname(path), p.get("Source")) for p in root.iter("Piece")]


def read_vtu_with_vtk(testcase, path):
    """Read @p path with VTK's vtkXMLUnstructuredGridReader (a .pvtu record and its pieces
    with vtkXMLPUnstructuredGridReader), failing @p testcase if a file is malformed
    (checked first without VTK, which can crash on such files) or if VTK reports an error
    or a warning.

    Returns {"n_points", "n_cells", "points", "cell_types", "point_data": {name: n x c array}}.
    """
    parallel = path.endswith(".pvtu")
    for piece in pvtu_pieces(path) if parallel else [path]:
        problems = decode_vtu(piece)["problems"]
        testcase.assertEqual(problems, [], "%s is not a valid VTU file" % os.path.basename(piece))

    from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader
    from vtkmodules.util.numpy_support import vtk_to_numpy

    events = []
    reader = vtkXMLPUnstructuredGridReader() if parallel else vtkXMLUnstructuredGridReader()
    reader.AddObserver("ErrorEvent", lambda obj, ev: events.append(ev))
    reader.AddObserver("WarningEvent", lambda obj, ev: events.append(ev))
    reader.SetFileName(path)
    reader.Update()
    testcase.assertEqual(events, [], "VTK reported problems reading %s" % path)
    grid = reader.GetOutput()
    pd = grid.GetPointData()
    data = {}
    for i in range(pd.GetNumberOfArrays()):
        arr = pd.GetArray(i)
        data[pd.GetArrayName(i)] = vtk_to_numpy(arr).reshape(arr.GetNumberOfTuples(),
                                                            arr.GetNumberOfComponents())
    n_points = grid.GetNumberOfPoints()
    points = (vtk_to_numpy(grid.GetPoints().GetData()).reshape(n_points, 3)
              if n_points else np.zeros((0, 3)))
    return {"n_points": n_points, "n_cells": grid.GetNumberOfCells(), "points": points,
            "cell_types": [grid.GetCellType(c) for c in range(grid.GetNumberOfCells())],
            "point_data": data}


class TempDirTestCase(unittest.TestCase):
    """A test with a fresh temporary directory self.tmp, removed afterwards."""

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="tribo-cli-")
        self.tmp = self._tmp.name

    def tearDown(self):
        # Give back permissions a test may have removed, so cleanup cannot fail.
        for base, dirs, files in os.walk(self.tmp):
            for name in dirs + files:
                try:
                    os.chmod(os.path.join(base, name), 0o700)
                except OSError:
                    pass
        self._tmp.cleanup()


def run_and_stop(testcase, cwd, case, out, sig, after_checkpoint_s=0.3):
    """Start `tribo run CASE --output OUT` in @p cwd and send @p sig once its first
    checkpoint exists (and @p after_checkpoint_s later); asserts the run was still going and
    the exit status (-9 for SIGKILL, 128 + N for a signal the run catches)."""
    proc = subprocess.Popen([TRIBO, "run", case, "--output", out, "--quiet"], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    checkpoint = os.path.join(cwd, out, "checkpoint.bin")
    deadline = time.monotonic() + 300
    while not os.path.exists(checkpoint):
        testcase.assertIsNone(proc.poll(), "the run ended before its first checkpoint")
        testcase.assertLess(time.monotonic(), deadline, "no checkpoint within 300 s")
        time.sleep(0.01)
    time.sleep(after_checkpoint_s)
    testcase.assertIsNone(proc.poll(), "the run ended before it could be stopped")
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=120)
    testcase.assertEqual(proc.returncode, -sig if sig == signal.SIGKILL else 128 + sig, stderr)
