#!/usr/bin/env bash
# The unit and command-line tests of common, gsa and forming under AddressSanitizer and
# UndefinedBehaviorSanitizer (the `sanitize` preset, gcc). The `long` and `verification`
# labels and the digitising suites are left out to fit CI's time (docs/reliability.md).
# Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset sanitize >/dev/null
cmake --build --preset sanitize --parallel "$(nproc)" --target common_tests gsa_tests forming_tests gsa simform
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd build-sanitize
ctest --output-on-failure --parallel "$(nproc)" --timeout 900 -R '^(common|gsa|forming)\.' -LE 'long|verification' \
  -E 'digitise|render|Render|Plots|docs' "$@"
