#!/usr/bin/env bash
# libFuzzer targets of the readers (tests/fuzz/README.md): builds them with the `fuzz`
# preset (clang, address + undefined sanitizers) and runs each one.
#
#   bash scripts/fuzz.sh smoke            # every target for SF_FUZZ_SECONDS (default 60) s
#   bash scripts/fuzz.sh ci               # every target, fixed seed and execution count (CI)
#   bash scripts/fuzz.sh long TARGET N    # one target for N executions (e.g. 1000000)
#
# Targets: grid csv mesh flc case stl. Corpora: tests/fuzz/corpus/<target> (seeds, read
# only) and build-fuzz/corpus/<target> (what the runs add). A finding (crash, sanitizer
# report, or an exception other than sf::Error) stops the run with exit 1 and leaves
# build-fuzz/findings/<target>/crash-*; minimise it with
#   build-fuzz/bin/fuzz_<target> -minimize_crash=1 -runs=10000 CRASH
# and add it as a regression test.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-smoke}
if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not found; skipping the fuzz targets"
  exit 0
fi
targets=(grid csv mesh flc case stl)
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --parallel "$(nproc)" --target $(printf 'fuzz_%s ' "${targets[@]}")

run() {  # target, extra libFuzzer options...
  local t=$1
  shift
  local seeds=tests/fuzz/corpus/$t
  [ "$t" = csv ] && seeds=tests/fuzz/corpus/grid
  mkdir -p "$corpus/$t" "build-fuzz/findings/$t"
  build-fuzz/bin/fuzz_$t -max_len=65536 -rss_limit_mb=2048 -timeout=20 \
    -artifact_prefix="build-fuzz/findings/$t/" -print_final_stats=1 "$@" "$corpus/$t" "$seeds" 2>&1 |
    grep -E '^(#[0-9]+.*(DONE|INITED)|stat::number_of_executed_units|==[0-9]+==ERROR|SUMMARY|finding:|Done)' || true
  return "${PIPESTATUS[0]}"
}

# Executions per target in `ci` mode: about 25 s each on 2 quiet cores (2.6 min in all). With a fixed seed
# and a fresh corpus the run is reproducible: what CI runs was run clean before landing.
declare -A ci_runs=([grid]=12000 [csv]=600000 [mesh]=120000 [flc]=300000 [case]=36000 [stl]=1000000)
corpus=build-fuzz/corpus
status=0
case "$mode" in
  smoke)
    for t in "${targets[@]}"; do
      echo "fuzz: $t for ${SF_FUZZ_SECONDS:-60} s"
      run "$t" -max_total_time="${SF_FUZZ_SECONDS:-60}" || { echo "fuzz: $t FOUND A PROBLEM (build-fuzz/findings/$t)"; status=1; }
    done
    ;;
  ci)
    corpus=build-fuzz/corpus-ci
    rm -rf "$corpus"
    for t in "${targets[@]}"; do
      echo "fuzz: $t for ${ci_runs[$t]} executions (seed 1)"
      run "$t" -seed=1 -runs="${ci_runs[$t]}" || { echo "fuzz: $t FOUND A PROBLEM (build-fuzz/findings/$t)"; status=1; }
    done
    ;;
  long)
    t=${2:?target}
    run "$t" -runs="${3:-1000000}" || { echo "fuzz: $t FOUND A PROBLEM (build-fuzz/findings/$t)"; status=1; }
    ;;
  *)
    echo "usage: scripts/fuzz.sh smoke | ci | long TARGET [EXECUTIONS]" >&2
    exit 2
    ;;
esac
exit "$status"
