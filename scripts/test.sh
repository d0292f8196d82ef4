#!/usr/bin/env bash
# Installs missing dependencies, builds Release and runs the whole test suite.
# Extra arguments go to ctest (e.g. -L verification, -LE long, -R '^gsa\.').
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --parallel "$(nproc)"
log=build/ctest.log
status=0
(cd build && ctest --output-on-failure --parallel "$(nproc)" --timeout 900 "$@") 2>&1 | tee "$log" || status=$?
# End with ctest's summary line (ctest lists disabled tests after it).
grep -E '^[0-9]+% tests passed' "$log" | tail -n 1 || true
exit "$status"
