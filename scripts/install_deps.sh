#!/usr/bin/env bash
# Installs the Debian 12 packages the suite builds on (see docs/ and shared DEPENDENCIES).
# A fast no-op when everything is present. Needs root (or sudo) only when something is missing.
set -euo pipefail

packages=(
  cmake g++ ninja-build pkg-config
  libeigen3-dev libsuitesparse-dev libopencv-dev libcgal-dev libvtk9-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
  libyaml-cpp-dev libfmt-dev xvfb xauth
  pybind11-dev python3-dev python3-numpy  # the Python module `sheetform` (python/, docs/python.md)
  dpkg-dev file  # cpack -G DEB: dpkg-shlibdeps finds the runtime packages of the .deb (docs/install.md)
  libmumps-seq-dev  # MUMPS 5.5 (sequential): symmetric-indefinite LDL^T of Newton tangents (common/linalg/solver.hpp)
  libopenblas0-serial  # optimised BLAS under CHOLMOD (reference BLAS is ~10x slower; serial: no spinning threads)
  libjs-three  # three.js r111, inlined into gsa's 3-D view (report.html, gsa view; gsa/view3d.hpp)
  chromium  # headless browser for the 3-D view's tests (tests/gsa/view3d_browser.py; skipped without it)
  clang libclang-rt-14-dev  # libFuzzer targets of the readers (scripts/fuzz.sh, run by scripts/extras.sh in CI)
  libomp-dev  # clang's OpenMP: the fuzz build compiles the real sf_forming (tests/fuzz/CMakeLists.txt)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${#missing[@]} missing packages: ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=300 "${missing[@]}"
