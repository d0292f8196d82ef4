#!/usr/bin/env bash
# Runs `gsa analyse` on every sample grid in data/gsa/ into results/<case>/.
set -euo pipefail
cd "$(dirname "$0")/.."
gsa=build/bin/gsa
for dir in data/gsa/*/; do
  name=$(basename "$dir")
  extra=()
  [ -f "$dir/options" ] && read -r -a extra < "$dir/options"
  "$gsa" analyse "$dir/grid.csv" --out "results/$name" "${extra[@]}"
done
echo "Results: $(ls -d results/*/ | tr '\n' ' ')"
echo "Open results/<case>/report.html for the pictures, results/<case>/deformed.vtp in ParaView; strains per mark are in results/<case>/strains.csv."
