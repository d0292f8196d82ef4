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
# SF_EXTRAS=1 (set by .ci/run) also runs the reliability extras of issue 20 within a time
# budget (scripts/extras.sh, docs/reliability.md): a fuzz run of every reader and the tests
# under the address and undefined-behaviour sanitizers.
if [ $# -eq 0 ] && [ "${SF_EXTRAS:-0}" = 1 ]; then
  # CI stops at 90 minutes: the extras get at most 50, and end by minute 80 of this script.
  minutes=$(((80 * 60 - SECONDS) / 60))
  [ "$minutes" -gt "${SF_EXTRAS_MINUTES:-50}" ] && minutes=${SF_EXTRAS_MINUTES:-50}
  bash scripts/extras.sh "$minutes" || status=1
fi
# End with ctest's summary line (ctest lists disabled tests after it).
grep -E '^[0-9]+% tests passed' "$log" | tail -n 1 || true
exit "$status"
