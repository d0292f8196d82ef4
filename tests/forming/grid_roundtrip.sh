#!/bin/sh
# simform run --grid-out -> gsa analyse: the virtual grid of a simulated uniaxial
# stretch (data/forming/uniaxial_0.yaml, edge pulled 1 mm on 100 mm, fibres along x)
# must give gsa's Green strain E1 = ((1.01)^2 - 1)/2 = 0.01005 at every mark, and the
# same lateral engineering strain as simform's own history.csv.
#
#   tests/forming/grid_roundtrip.sh SIMFORM GSA SOURCE_DIR WORK_DIR
set -eu
simform=$1
gsa=$2
src=$3
work=$4
rm -rf "$work"
mkdir -p "$work"
"$simform" -q run "$src/data/forming/uniaxial_0.yaml" --out "$work/run" --grid-out "$work/run/grid.csv" --grid-marks 11
"$gsa" -q analyse "$work/run/grid.csv" --out "$work/gsa" --no-plots
# gsa's summary.json is read in CMake script mode (string(JSON)), the numbers compared
# with awk: no other tools needed.
cat > "$work/values.cmake" <<'CMAKE'
file(READ "${WORK}/gsa/summary.json" s)
string(JSON n GET "${s}" counts points)
string(JSON ok GET "${s}" counts by_status ok)
set(out "${n} ${ok}")
foreach(field E1 eng2)
  foreach(k min max)
    string(JSON v GET "${s}" strain_ranges ${field} ${k})
    string(APPEND out " ${v}")
  endforeach()
endforeach()
file(WRITE "${WORK}/values.txt" "${out}\n")
CMAKE
cmake -DWORK="$work" -P "$work/values.cmake"
# tool_uy (column 4) of the last row: mean uy over the pulled edge = eps2 * Ly / 2, Ly = 20 mm.
uy=$(tail -n 1 "$work/run/history.csv" | cut -d, -f4)
# Exact E1 = ((1.01)^2 - 1)/2; the surface fit reproduces a homogeneous stretch to
# round-off (measured 9e-14): tolerance 1e-8, also for eng2 against simform's eps2.
awk -v uy="$uy" '
  function abs(x) { return x < 0 ? -x : x }
  {
    n = $1; ok = $2; e1min = $3; e1max = $4; e2min = $5; e2max = $6
    exact = (1.01 * 1.01 - 1) / 2; eps2 = uy / 10; tol = 1e-8
    if (n != 121 || ok != 121) { print "expected 121 of 121 marks analysed, found " ok " of " n; exit 1 }
    if (abs(e1min - exact) > tol || abs(e1max - exact) > tol) { printf "E1 %.12g..%.12g, exact %.12g\n", e1min, e1max, exact; exit 1 }
    if (abs(e2min - eps2) > tol || abs(e2max - eps2) > tol) { printf "eng2 %.12g..%.12g, simform %.12g\n", e2min, e2max, eps2; exit 1 }
    printf "grid round trip ok: E1 %.12g..%.12g (exact %.12g), eng2 %.9g (simform %.9g)\n", e1min, e1max, exact, e2min, eps2
  }' "$work/values.txt"
