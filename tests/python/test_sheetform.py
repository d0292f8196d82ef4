"""Tests of the Python module sheetform (ctest python.sheetform; docs/python.md).

Environment (set by tests/install_tests.cmake): PYTHONPATH holds build/python; SF_GSA is
the gsa executable; SF_SOURCE_DIR the repository; SF_WORK_DIR a scratch folder.
"""

import os
import shutil
import subprocess
import unittest

import numpy as np

import sheetform

GSA = os.environ.get("SF_GSA", "gsa")
SRC = os.environ.get("SF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
WORK = os.environ.get("SF_WORK_DIR", "/tmp/sheetform-python-tests")

SAMPLES = {
    "dome": {},
    "cylinder": {},
    "dome_noisy": {},
    "trellis": {"fibres": (0, 90)},
}
NUMERIC = ["element", "xi1", "xi2", "lambda1", "lambda2", "E1", "E2", "eng1", "eng2", "true1", "true2",
           "thickness_change_pct", "dir1_x", "dir1_y", "dir1_z", "dir2_x", "dir2_y", "dir2_z", "residual",
           "residual_undeformed"]


def grid_path(case):
    return os.path.join(SRC, "data", "gsa", case, "grid.csv")


def cli_options(options):
    args = []
    for key, value in options.items():
        if isinstance(value, (tuple, list)):
            value = ",".join(str(v) for v in value)
        args += ["--" + key.replace("_", "-"), str(value)]
    return args


def run_cli(*args):
    return subprocess.run([GSA] + list(args), capture_output=True, text=True)


def read_grid_arrays(path):
    """The grid file's columns with NumPy only (id,X,Y,Z,x,y,z,i,j)."""
    with open(path) as f:
        lines = [l.rstrip("\n") for l in f if l.strip() and not l.startswith("#")]
    header = lines[0].split(",")
    rows = [l.split(",") for l in lines[1:]]
    col = {name: [r[k] for r in rows] for k, name in enumerate(header)}

    def num(name):
        return np.array([float(v) if v not in ("", "nan") else np.nan for v in col[name]])

    U = np.column_stack([num("X"), num("Y"), num("Z")])
    D = np.column_stack([num("x"), num("y"), num("z")])
    ij = np.column_stack([num("i"), num("j")]).astype(int) if "i" in col else None
    return col["id"], U, D, ij


def max_difference(a, b, columns):
    worst = 0.0
    for c in columns:
        x, y = np.asarray(a[c], float), np.asarray(b[c], float)
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            raise AssertionError("column %s: NaN in different rows" % c)
        m = ~np.isnan(x)
        if m.any():
            worst = max(worst, float(np.max(np.abs(x[m] - y[m]))))
    return worst


class SameAsCommandLine(unittest.TestCase):
    """sheetform.analyse gives the numbers gsa analyse writes, on every sample."""

    @classmethod
    def setUpClass(cls):
        os.makedirs(WORK, exist_ok=True)
        cls.cli = {}
        for case, options in SAMPLES.items():
            out = os.path.join(WORK, case)
            shutil.rmtree(out, ignore_errors=True)
            p = run_cli("--quiet", "analyse", grid_path(case), "--out", out, "--no-plots", *cli_options(options))
            if p.returncode != 0:
                raise RuntimeError("gsa analyse %s failed: %s" % (case, p.stderr))
            cls.cli[case] = sheetform.read_results(out, as_frame=False)

    def test_file_input_equals_cli(self):
        for case, options in SAMPLES.items():
            with self.subTest(case=case):
                r = sheetform.analyse(grid_path(case), as_frame=False, **options)
                cli = self.cli[case].points
                self.assertEqual(list(r.points["id"]), list(cli["id"]))
                self.assertEqual(list(r.points["status"]), list(cli["status"]))
                columns = NUMERIC + (["shear_angle_deg", "fibre1_stretch", "fibre2_stretch"] if options else [])
                diff = max_difference(r.points, cli, columns)
                # strains.csv holds the shortest round-trip text of each double: equal bits.
                self.assertLessEqual(diff, 1e-12, "%s: max |python - cli| = %g" % (case, diff))
                self.assertEqual(r.summary["counts"], self.cli[case].summary["counts"])
                self.assertEqual(r.summary["fit"], self.cli[case].summary["fit"])

    def test_array_input_equals_cli(self):
        for case, options in SAMPLES.items():
            with self.subTest(case=case):
                ids, U, D, ij = read_grid_arrays(grid_path(case))
                r = sheetform.analyse(U, D, ids=ids, ij=ij, as_frame=False, **options)
                diff = max_difference(r.points, self.cli[case].points, NUMERIC)
                self.assertLessEqual(diff, 1e-12, "%s: max |python(arrays) - cli| = %g" % (case, diff))

    def test_triangles_method(self):
        out = os.path.join(WORK, "dome_triangles")
        shutil.rmtree(out, ignore_errors=True)
        p = run_cli("--quiet", "analyse", grid_path("dome"), "--out", out, "--no-plots", "--method", "triangles")
        self.assertEqual(p.returncode, 0, p.stderr)
        r = sheetform.analyse(grid_path("dome"), method="triangles", as_frame=False)
        self.assertIsNone(r.surface)
        cli = sheetform.read_results(out, as_frame=False).points
        self.assertLessEqual(max_difference(r.points, cli, ["E1", "E2", "thickness_change_pct"]), 1e-12)


class Surfaces(unittest.TestCase):
    def test_read_results_surfaces_equal_the_folders_strains(self):
        out = os.path.join(WORK, "dome_surfaces")
        shutil.rmtree(out, ignore_errors=True)
        p = run_cli("--quiet", "analyse", grid_path("dome"), "--out", out, "--no-plots")
        self.assertEqual(p.returncode, 0, p.stderr)
        r = sheetform.read_results(out, as_frame=False)
        self.assertIsNotNone(r.surface)
        ok = np.array([s == "ok" for s in r.points["status"]])
        element = r.points["element"][ok].astype(int)
        xi = np.column_stack([r.points["xi1"][ok], r.points["xi2"][ok]])
        v = r.surface.evaluate(element, xi)
        for c in ("E1", "E2", "thickness_change_pct"):
            # strains.csv keeps xi to round-trip precision: the surfaces give the marks' strains.
            self.assertLess(np.max(np.abs(v[c] - r.points[c][ok])), 1e-10, c)

    def test_evaluate_at_marks_equals_point_strains(self):
        r = sheetform.analyse(grid_path("dome"), as_frame=False)
        ok = np.array([s == "ok" for s in r.points["status"]])
        element = r.points["element"][ok].astype(int)
        xi = np.column_stack([r.points["xi1"][ok], r.points["xi2"][ok]])
        v = r.surface.evaluate(element, xi)
        for c in ("E1", "E2", "true1", "thickness_change_pct"):
            self.assertLess(np.max(np.abs(v[c] - r.points[c][ok])), 1e-12, c)
        self.assertEqual(v["X"].shape, (ok.sum(), 3))
        one = r.surface.evaluate(int(element[0]), xi[0])
        self.assertAlmostEqual(one["E1"], r.points["E1"][ok][0], places=12)
        self.assertEqual(one["x"].shape, (3,))

    def test_rigid_motion_gives_zero_strain_everywhere(self):
        grid = os.path.join(WORK, "rigid.csv")
        p = run_cli("--quiet", "synth", "rigid", "--out", grid)
        self.assertEqual(p.returncode, 0, p.stderr)
        r = sheetform.analyse(grid, as_frame=False)
        n = r.surface.n_elements
        t = np.linspace(0.0, 1.0, 5)
        xi = np.array([(a, b) for a in t for b in t])
        element = np.repeat(np.arange(n), len(xi))
        v = r.surface.evaluate(element, np.tile(xi, (n, 1)))
        worst = max(np.max(np.abs(v["E1"])), np.max(np.abs(v["E2"])))
        self.assertLess(worst, 1e-6, "rigid motion: max |E| = %g over %d points" % (worst, len(element)))

    def test_evaluate_outside_the_mesh_raises(self):
        r = sheetform.analyse(grid_path("cylinder"), as_frame=False)
        with self.assertRaisesRegex(sheetform.InputError, "not an element of the mesh"):
            r.surface.evaluate(r.surface.n_elements, (0.5, 0.5))
        with self.assertRaisesRegex(sheetform.InputError, "outside the element"):
            r.surface.evaluate(0, (1.5, 0.5))


class Errors(unittest.TestCase):
    """Errors are Python exceptions with the command line's messages."""

    def cli_message(self, *args):
        p = run_cli("--quiet", "analyse", *args, "--out", os.path.join(WORK, "never"), "--no-plots")
        self.assertNotEqual(p.returncode, 0)
        line = p.stderr.strip().splitlines()[0]
        for prefix in ("gsa: error: ", "gsa: "):
            if line.startswith(prefix):
                return p.returncode, line[len(prefix):]
        return p.returncode, line

    def test_bad_option_value(self):
        code, message = self.cli_message(grid_path("dome"), "--smoothing-scale", "-1")
        self.assertEqual(code, 2)
        with self.assertRaises(sheetform.UsageError) as cm:
            sheetform.analyse(grid_path("dome"), smoothing_scale=-1)
        self.assertEqual(str(cm.exception), message)
        self.assertIn("--smoothing-scale", message)

    def test_missing_file(self):
        missing = os.path.join(WORK, "no-such-grid.csv")
        code, message = self.cli_message(missing)
        self.assertEqual(code, 1)
        with self.assertRaises(sheetform.InputError) as cm:
            sheetform.analyse(missing)
        self.assertEqual(str(cm.exception), message)

    def test_bad_cell(self):
        bad = os.path.join(WORK, "bad_cell.csv")
        os.makedirs(WORK, exist_ok=True)
        with open(grid_path("dome")) as f, open(bad, "w") as g:
            for k, line in enumerate(f):
                g.write(line.replace("P0_1,-45,", "P0_1,-4x5,") if k == 5 else line)
        code, message = self.cli_message(bad)
        self.assertEqual(code, 1)
        with self.assertRaises(sheetform.InputError) as cm:
            sheetform.analyse(bad)
        self.assertEqual(str(cm.exception), message)
        self.assertIn("bad_cell.csv:6", message)

    def test_array_problems(self):
        U = np.zeros((10, 3))
        with self.assertRaisesRegex(sheetform.InputError, "deformed: 9 rows"):
            sheetform.analyse(U, np.zeros((9, 3)))
        with self.assertRaisesRegex(sheetform.InputError, r"shape \(n, 3\)"):
            sheetform.analyse(np.zeros((10, 2)), np.zeros((10, 2)))
        with self.assertRaisesRegex(sheetform.InputError, "repeated"):
            sheetform.analyse(U, U, ids=["a"] * 10)
        with self.assertRaises(sheetform.InputError):  # all marks at one point: nothing to fit
            sheetform.analyse(U, U)
        # Marks two grid steps apart form no triangle: refused as by gsa analyse.
        U4 = np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]], dtype=float)
        with self.assertRaisesRegex(sheetform.InputError, r"no mark could be analysed \(4 no_triangle\)"):
            sheetform.analyse(U4, U4 * 1.01, ij=[[0, 0], [2, 0], [0, 2], [2, 2]], method="triangles")
        with self.assertRaisesRegex(sheetform.UsageError, "unknown option 'smoothing'"):
            sheetform.analyse(U, U, smoothing=2)
        with self.assertRaisesRegex(sheetform.UsageError, "--alpha: expected a number"):
            sheetform.analyse(U, U, alpha="x")

    def test_read_results_of_a_folder_without_results(self):
        empty = os.path.join(WORK, "empty")
        os.makedirs(empty, exist_ok=True)
        with self.assertRaisesRegex(sheetform.InputError, "no strains.csv here"):
            sheetform.read_results(empty)
        self.assertTrue(issubclass(sheetform.InputError, sheetform.Error))
        self.assertTrue(issubclass(sheetform.Error, RuntimeError))


class Frames(unittest.TestCase):
    def test_points_table_kind(self):
        r = sheetform.analyse(grid_path("dome"))
        try:
            import pandas  # noqa: F401
        except ImportError:
            self.assertIsInstance(r.points, dict)
            self.assertIsInstance(r.points["E1"], np.ndarray)
            return
        self.assertEqual(type(r.points).__name__, "DataFrame")
        self.assertEqual(len(r.points), 441)


if __name__ == "__main__":
    unittest.main()
