#!/usr/bin/env bash
# The reliability extras of issue 20 (docs/reliability.md), run by `scripts/test.sh` when
# SF_EXTRAS=1 (CI sets it): a short fuzz run of every reader (clang, libFuzzer), then the
# readers' tests under the address and undefined-behaviour sanitizers
# (SF_EXTRAS_SANITIZE=readers, the default; full: the whole sanitize suite; 0: none).
#
#   bash scripts/extras.sh [MINUTES]     # time budget, default SF_EXTRAS_MINUTES or 50
#
# A finding or a failing sanitized test fails the run (exit 1). What does not fit in the
# budget is stopped and reported as not run, so a slow machine cannot push CI past its
# limit; the last lines say what ran. Logs: build/fuzz.log, build/sanitize.log.
set -uo pipefail
cd "$(dirname "$0")/.."
budget=$((${1:-${SF_EXTRAS_MINUTES:-50}} * 60))
deadline=$((SECONDS + budget))
left() { echo $((deadline - SECONDS)); }
mkdir -p build
status=0
summary=()

# 1. Fuzzing: every reader, a fixed seed and execution count (scripts/fuzz.sh ci).
if command -v clang++ >/dev/null; then
  echo "extras: fuzzing every reader (build-fuzz, about 30 s each), log build/fuzz.log"
  timeout -k 10 "$(left)" bash scripts/fuzz.sh ci >build/fuzz.log 2>&1
  rc=$?
  runs=$(grep -E '^stat::number_of_executed_units' build/fuzz.log | awk '{s += $2} END {print s + 0}')
  if [ $rc -eq 124 ]; then
    summary+=("fuzz: stopped at the time budget after $runs executions")
  elif [ $rc -ne 0 ]; then
    status=1
    summary+=("fuzz: FAILED (finding or build error; build/fuzz.log, build-fuzz/findings/)")
  else
    summary+=("fuzz: $(grep -c '^fuzz: .* for ' build/fuzz.log) readers, $runs executions, no findings")
  fi
else
  summary+=("fuzz: not run (clang++ not installed)")
fi

# 2. Sanitizers: by default the readers' tests (scripts/sanitize.sh readers: the common
# suite, built in the fuzz tree beside the fuzz targets, so only its test files are added);
# SF_EXTRAS_SANITIZE=full runs the whole gcc sanitize suite instead (about 230 files to
# build: more than CI's time, docs/reliability.md), SF_EXTRAS_SANITIZE=0 none.
sanitize=${SF_EXTRAS_SANITIZE:-readers}
[ "$sanitize" = 1 ] && sanitize=full
if [ "$sanitize" = 0 ]; then
  summary+=("sanitize: not run (SF_EXTRAS_SANITIZE=0)")
elif ! command -v clang++ >/dev/null && [ "$sanitize" = readers ]; then
  summary+=("sanitize: not run (clang++ not installed)")
elif [ "$(left)" -le 60 ]; then
  summary+=("sanitize: not run (time budget used up)")
else
  echo "extras: $sanitize tests under address+undefined sanitizers, log build/sanitize.log"
  timeout -k 10 "$(left)" bash scripts/sanitize.sh "$sanitize" >build/sanitize.log 2>&1
  rc=$?
  passed=$(grep -cE '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* Passed' build/sanitize.log)
  failed=$(grep -cE '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .*(\*\*\*|Not Run)' build/sanitize.log)
  if [ $rc -eq 124 ]; then
    summary+=("sanitize ($sanitize): stopped at the time budget: $passed tests passed, $failed failed before the stop")
    [ "$failed" -gt 0 ] && status=1
  elif [ $rc -ne 0 ]; then
    status=1
    summary+=("sanitize ($sanitize): FAILED: $passed passed, $failed failed (build/sanitize.log)")
  else
    summary+=("sanitize ($sanitize): $(grep -E '^[0-9]+% tests passed' build/sanitize.log | tail -n 1)")
  fi
fi
printf '%s\n' "${summary[@]}" | tee build/extras.log
echo "extras: $((SECONDS)) s of a $budget s budget"
exit "$status"
