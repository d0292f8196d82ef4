#!/usr/bin/env bash
# Throughput of `gsa batch` (docs/batch.md): N synthetic parts of M x M marks each
# (default 100 parts of 100 x 100 = 10 000 marks, the dome of `gsa synth` with 0.01 mm
# noise, every part its own seed), analysed with --no-plots at -j 1 and -j JOBS.
# Prints parts per minute and seconds per part.
# Usage: bench/batch_throughput.sh [GSA] [PARTS] [MARKS_PER_SIDE] [JOBS]
set -euo pipefail
gsa=${1:-build/bin/gsa}
parts=${2:-100}
n=${3:-100}
jobs=${4:-2}
gsa=$(cd "$(dirname "$gsa")" && pwd)/$(basename "$gsa")
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sf-batch-bench.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/parts"
for ((k = 1; k <= parts; k++)); do
  "$gsa" --quiet synth dome --n "$n" --spacing $(awk "BEGIN { print 100 / ($n - 1) }") --noise 0.01 \
    --seed "$k" --out "$tmp/parts/part$(printf %04d "$k").csv"
done
echo "batch_throughput: $parts parts of $((n * n)) marks each in $tmp/parts"
for j in 1 "$jobs"; do
  [ "$j" = 1 ] && [ "$jobs" = 1 ] && continue
  start=$(date +%s.%N)
  "$gsa" --quiet batch "$tmp/parts" --out "$tmp/out-j$j" -j "$j" --options "--no-plots"
  end=$(date +%s.%N)
  awk -v p="$parts" -v s="$start" -v e="$end" -v j="$j" -v m=$((n * n)) 'BEGIN {
    t = e - s; printf "batch_throughput: -j %d: %d parts of %d marks in %.1f s: %.1f parts/min, %.2f s per part\n",
    j, p, m, t, 60 * p / t, t / p }'
  ok=$(grep -c ',ok,' "$tmp/out-j$j/batch.csv")
  echo "batch_throughput: -j $j: $ok of $parts parts ok"
done
