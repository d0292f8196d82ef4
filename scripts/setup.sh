#!/usr/bin/env bash
# Fresh machine to first results: install packages, build, analyse the sample grid in data/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
bash scripts/run_samples.sh
