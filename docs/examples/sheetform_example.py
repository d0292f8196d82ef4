#!/usr/bin/env python3
# sheetform from Python, notebook style: run it cell by cell (# %% marks the cells in
# VS Code / Jupytext), or as a script from the repository root:
#
#   PYTHONPATH=build/python python3 docs/examples/sheetform_example.py
#
# It analyses the sample dome three ways (a grid file, NumPy arrays, a results folder of
# the command line), looks at the strains along a line across the part with the fitted
# surfaces, checks the thinning against a limit, and shows what an error looks like.
# Lengths in mm, strains dimensionless (true = logarithmic), thickness change in percent.

# %% Imports: NumPy is needed, pandas is used when installed (result.points a DataFrame).
import os
import subprocess
import tempfile

import numpy as np

import sheetform

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
grid_file = os.path.join(root, "data", "gsa", "dome", "grid.csv")
print("sheetform", sheetform.__version__)

# %% 1. A grid file, read exactly as `gsa analyse` reads it. Options are gsa analyse's
# flags without the dashes: smoothing_scale=1.5 is --smoothing-scale 1.5.
result = sheetform.analyse(grid_file, as_frame=False)
points = result.points  # dict of NumPy arrays: strains.csv's columns
print(result)
print("marks with a strain:", int(np.isfinite(points["E1"]).sum()), "of", len(points["id"]))
print("max major true strain: %.4f" % np.nanmax(points["true1"]))
print("max thinning: %.2f %%" % -np.nanmin(points["thickness_change_pct"]))
print("fit RMS residual, deformed surface: %.2g mm" % result.summary["fit"]["deformed"]["rms_residual"])

# %% 2. The same marks as arrays, as they come out of a measuring system's API or a
# pandas table: (n, 3) positions before and after forming; NaN rows: not digitised.
ids, U, D = [], [], []
with open(grid_file) as f:
    rows = [line.strip().split(",") for line in f if line.strip() and not line.startswith("#")]
header = rows[0]
c = {name: k for k, name in enumerate(header)}
for r in rows[1:]:
    ids.append(r[c["id"]])
    U.append([float(r[c[k]]) for k in ("X", "Y", "Z")])
    D.append([float(r[c[k]]) for k in ("x", "y", "z")])
U, D = np.array(U), np.array(D)
D[17] = np.nan  # pretend mark 18 was not found after forming
from_arrays = sheetform.analyse(U, D, ids=ids, as_frame=False)
print("status of mark", ids[17], "->", from_arrays.points["status"][17])

# %% 3. Strains anywhere on the part: the fitted surfaces, evaluated at (element, xi).
# Here along the line of marks through the pole: element and xi of those marks, plus
# the element midpoints in between.
surface = result.surface
line = [k for k, i in enumerate(ids) if i.endswith("_10")]  # marks P<i>_10: the middle column
element = points["element"][line].astype(int)
xi = np.column_stack([points["xi1"][line], points["xi2"][line]])
along = surface.evaluate(element, xi)
for k in range(0, len(line), 5):
    print("Y = %6.1f mm: major %.4f, minor %.4f (true), thickness %+.2f %%"
          % (along["X"][k, 1], along["true1"][k], along["true2"][k], along["thickness_change_pct"][k]))
centre = surface.evaluate(0, (0.5, 0.5))  # one point: scalars and 3-vectors
print("element 0 centre: X =", np.round(centre["X"], 3), "major true strain %.4f" % centre["true1"])

# %% 4. A limit check, as a test engineer would script it: thinning beyond 15 %?
too_thin = points["thickness_change_pct"] < -15.0
print("marks thinned by more than 15 %%: %d (%s ...)" % (too_thin.sum(), ", ".join(np.asarray(ids)[too_thin][:3])))

# %% 5. Results of the command line (gsa analyse or gsa batch) read back.
with tempfile.TemporaryDirectory() as tmp:
    gsa = os.path.join(root, "build", "bin", "gsa")
    if os.path.exists(gsa):
        subprocess.run([gsa, "--quiet", "analyse", grid_file, "--out", tmp, "--no-plots"], check=True)
        cli = sheetform.read_results(tmp, as_frame=False)
        print("max |E1(python) - E1(gsa analyse)| =", np.nanmax(np.abs(cli.points["E1"] - points["E1"])))

# %% 6. Errors are exceptions with the command line's messages.
try:
    sheetform.analyse(grid_file, smoothing_scale=0)
except sheetform.UsageError as e:
    print("UsageError:", e)
try:
    sheetform.analyse(U[:3], D[:3])
except sheetform.InputError as e:
    print("InputError:", e)
