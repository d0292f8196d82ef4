#!/usr/bin/env bash
# Runs `gsa analyse` on every sample grid in data/gsa/ into results/<case>/, and
# `simform run` on every sample case in data/forming/ into results/forming/<case>/.
set -euo pipefail
cd "$(dirname "$0")/.."
gsa=build/bin/gsa
simform=build/bin/simform
for dir in data/gsa/*/; do
  name=$(basename "$dir")
  extra=()
  [ -f "$dir/options" ] && read -r -a extra < "$dir/options"
  "$gsa" analyse "$dir/grid.csv" --out "results/$name" "${extra[@]}"
done
for case in data/forming/*.yaml; do
  name=$(basename "$case" .yaml)
  "$simform" run "$case" --out "results/forming/$name"
done
echo "Results: $(ls -d results/*/ results/forming/*/ | tr '\n' ' ')"
echo "Open results/<case>/report.html for the pictures, results/<case>/deformed.vtp in ParaView; strains per mark are in results/<case>/strains.csv."
echo "Forming runs: open results/forming/<case>/result.pvd in ParaView; history.csv has load, reaction and energy per step."
