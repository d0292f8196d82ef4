#!/usr/bin/env bash
# Installs missing dependencies, then configures and builds Release into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --parallel "$(nproc)"
