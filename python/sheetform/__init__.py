"""sheetform: grid strain analysis (`gsa analyse`) from Python.

    import numpy as np, sheetform
    r = sheetform.analyse(undeformed, deformed)        # (n, 3) arrays, NaN rows: not digitised
    r = sheetform.analyse("part.csv", fibres=(0, 90))  # or a grid file, as gsa analyse reads it
    r.points["E1"], r.summary["fit"], r.surface.evaluate(element, (0.5, 0.5))
    r = sheetform.read_results("results/dome")         # a folder written by gsa analyse

The options are those of `gsa analyse` without the dashes, '-' written '_'
(smoothing_scale=2 is --smoothing-scale 2). Errors raise sheetform.InputError (bad data)
or sheetform.UsageError (bad options), both sheetform.Error, with the command line's
messages. See docs/python.md.
"""

import json
import os

import numpy as np

from . import _core
from ._core import Error, InputError, Surface, UsageError

__all__ = ["analyse", "read_results", "Result", "Surface", "Error", "InputError", "UsageError", "__version__"]
__version__ = _core.version

try:  # pandas is optional: points become a DataFrame when it is installed
    import pandas as _pandas
except ImportError:  # pragma: no cover - depends on the machine
    _pandas = None


def _table(columns, as_frame):
    """The per-point columns as a dict of NumPy arrays, or a pandas DataFrame."""
    table = {}
    for name, values in columns.items():
        if isinstance(values, list):
            table[name] = np.asarray(values, dtype=object)
        else:
            table[name] = values
    if as_frame and _pandas is not None:
        return _pandas.DataFrame(table)
    return table


class Result:
    """One analysed part.

    points   per-point results: strains.csv's columns (id, status, element, xi1, xi2,
             lambda1, lambda2, E1, E2, eng1, eng2, true1, true2, thickness_change_pct,
             dir1_x, ...); a dict of NumPy arrays, or a pandas DataFrame when pandas is
             installed (unless as_frame=False). Numbers are float64, NaN where the mark
             was not analysed (its status says why).
    summary  summary.json's content as a dict (fit residuals, smoothing, strain ranges...).
    surface  the fitted surfaces (Surface; surface method only, else None):
             surface.evaluate(element, xi) -> dict of X, x, lambda1, lambda2, E1, E2,
             eng1, eng2, true1, true2, thickness_change_pct, dir1, dir2 (and fibres).
    warnings the analysis' warnings (list of str).
    """

    def __init__(self, points, summary, surface=None, warnings=()):
        self.points = points
        self.summary = summary
        self.surface = surface
        self.warnings = list(warnings)

    def __repr__(self):
        n = len(self.points["id"]) if self.points is not None else 0
        method = (self.summary or {}).get("parameters", {}).get("method", "?")
        return "<sheetform.Result: %d points, method %s%s>" % (
            n, method, ", with surfaces" if self.surface is not None else "")


def analyse(undeformed, deformed=None, ids=None, ij=None, as_frame=True, **options):
    """Grid strain analysis of one part, as `gsa analyse` does it.

    undeformed, deformed: (n, 3) arrays of mark positions before and after forming (rows
        of NaN where a mark was not digitised), in the length unit `units` (default mm);
        or undeformed a grid file path (deformed None: a file holding both states; or two
        files, undeformed and deformed, each id,x,y,z).
    ids: n mark labels (default "1".."n"); ij: optional (n, 2) grid row/column indices.
    options: gsa analyse's options, e.g. method="triangles", fibres=(0, 90),
        elements="8x8", smoothing_scale=2.0, no_local_smoothing=True, units="mm";
        reading options (format, columns, delimiter, ...) for files.
    Returns a Result. Raises InputError / UsageError with gsa's messages.
    """
    if isinstance(undeformed, (str, os.PathLike)):
        if ids is not None or ij is not None:
            raise UsageError("ids and ij come from the file when analysing a grid file")
        if deformed is None:
            raw = _core.analyse_files(os.fspath(undeformed), "", "", options)
        elif isinstance(deformed, (str, os.PathLike)):
            raw = _core.analyse_files("", os.fspath(undeformed), os.fspath(deformed), options)
        else:
            raise UsageError("deformed: give a file path too when undeformed is a file path")
    else:
        if deformed is None:
            raise UsageError("deformed: the (n, 3) array of deformed positions is missing")
        raw = _core.analyse_arrays(undeformed, deformed, ids, ij, options)
    return Result(_table(raw["columns"], as_frame), json.loads(raw["summary_json"]), raw["surface"],
                  raw["warnings"])


def read_results(dir, as_frame=True):
    """A results folder written by `gsa analyse` (or `gsa batch`): strains.csv as points,
    summary.json as summary, and the fitted surfaces from surfaces.json (written by the
    surface method), evaluable anywhere as after analyse(); surface is None for the
    triangles method or a folder written before surfaces.json existed."""
    raw = _core.read_results(os.fspath(dir))
    return Result(_table(raw["columns"], as_frame), json.loads(raw["summary_json"]), raw["surface"])
