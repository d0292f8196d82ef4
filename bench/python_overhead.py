#!/usr/bin/env python3
"""Overhead of the Python call against the command line (docs/python.md).

A synthetic dome of N x N marks (default 317 x 317 = 100 489, about 1e5), analysed
  - by the command line:  gsa --quiet analyse grid.csv --out DIR --no-plots (a new process:
    start-up, reading the CSV, writing strains.csv, summary.json and the .vtp surfaces);
  - by sheetform.analyse(path)   (reading the same file, no output files);
  - by sheetform.analyse(U, D)   (NumPy arrays in, NumPy arrays out).
Each is run REPEATS times, alternating; the best and median wall times are printed.
Usage: PYTHONPATH=build/python python3 bench/python_overhead.py [GSA] [N] [REPEATS]
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import sheetform

gsa = sys.argv[1] if len(sys.argv) > 1 else "build/bin/gsa"
n = int(sys.argv[2]) if len(sys.argv) > 2 else 317
repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 3

with tempfile.TemporaryDirectory() as tmp:
    grid = os.path.join(tmp, "grid.csv")
    subprocess.run([gsa, "--quiet", "synth", "dome", "--n", str(n), "--spacing", str(100.0 / (n - 1)),
                    "--noise", "0.01", "--out", grid], check=True)
    # The arrays, read once (as a notebook would have them).
    r0 = sheetform.read_results  # noqa: F841  (import check)
    with open(grid) as f:
        rows = [l.split(",") for l in f if l.strip() and not l.startswith("#")]
    header, rows = rows[0], rows[1:]
    col = {name: k for k, name in enumerate(h.strip() for h in header)}
    U = np.array([[float(r[col[c]]) for c in "XYZ"] for r in rows])
    D = np.array([[float(r[col[c]]) for c in "xyz"] for r in rows])
    ids = [r[col["id"]] for r in rows]
    print("python_overhead: %d marks" % len(ids))

    times = {"cli": [], "python(path)": [], "python(arrays)": []}
    for k in range(repeats):
        out = os.path.join(tmp, "out%d" % k)
        t = time.perf_counter()
        subprocess.run([gsa, "--quiet", "analyse", grid, "--out", out, "--no-plots"], check=True)
        times["cli"].append(time.perf_counter() - t)
        t = time.perf_counter()
        rp = sheetform.analyse(grid, as_frame=False)
        times["python(path)"].append(time.perf_counter() - t)
        t = time.perf_counter()
        ra = sheetform.analyse(U, D, ids=ids, as_frame=False)
        times["python(arrays)"].append(time.perf_counter() - t)
    cli = sheetform.read_results(out, as_frame=False)
    diff = np.nanmax(np.abs(ra.points["E1"] - cli.points["E1"]))
    for name, ts in times.items():
        print("python_overhead: %-15s best %.2f s, median %.2f s (%d runs)" % (
            name, min(ts), statistics.median(ts), len(ts)))
    base = min(times["cli"])
    for name in ("python(path)", "python(arrays)"):
        print("python_overhead: %s / cli = %.2f (best times)" % (name, min(times[name]) / base))
    print("python_overhead: max |E1(python arrays) - E1(cli)| = %g" % diff)
