#!/usr/bin/env bash
# Tests under AddressSanitizer and UndefinedBehaviorSanitizer (docs/reliability.md).
#
#   bash scripts/sanitize.sh            # readers: the common tests (CSV and grid files, measuring-
#                                       # system formats, STL, results folders, meshes), what CI runs
#   bash scripts/sanitize.sh full       # the unit and command-line tests of common, gsa and forming
#                                       # (gcc, the `sanitize` preset; about 230 files to build)
#
# `readers` builds in the fuzz tree (clang, the `fuzz` preset): its sf_common is already
# compiled with both sanitizers for the fuzz targets, so only the test files are added.
# Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=readers
if [ "${1:-}" = full ] || [ "${1:-}" = readers ]; then
  mode=$1
  shift
fi
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if [ "$mode" = readers ]; then
  if ! command -v clang++ >/dev/null; then
    echo "sanitize: clang++ not found; the readers' tests under sanitizers need it (scripts/install_deps.sh)" >&2
    exit 1
  fi
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz --parallel "$(nproc)" --target common_tests
  cd build-fuzz
  ctest --output-on-failure --parallel "$(nproc)" --timeout 900 -R '^common\.' -LE 'long|verification' \
    -E 'render|Render|Plots' "$@"
  exit 0
fi
cmake --preset sanitize >/dev/null
cmake --build --preset sanitize --parallel "$(nproc)" --target common_tests gsa_tests forming_tests gsa simform
cd build-sanitize
ctest --output-on-failure --parallel "$(nproc)" --timeout 900 -R '^(common|gsa|forming)\.' -LE 'long|verification' \
  -E 'digitise|render|Render|Plots|docs' "$@"
