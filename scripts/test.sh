#!/usr/bin/env bash
# Installs missing dependencies, builds Release and runs the whole test suite.
# Extra arguments go to ctest (e.g. -L verification, -LE long, -R '^gsa\.').
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd build
ctest --output-on-failure --parallel "$(nproc)" --timeout 900 "$@"
