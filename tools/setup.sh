#!/usr/bin/env bash
# Installs isolink's Debian 12 dependencies (when missing) and builds into ./build.
#   bash tools/setup.sh                      # Release build
#   ISOLINK_CMAKE_ARGS="-DISOLINK_WERROR=ON" bash tools/setup.sh
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ccache pkg-config python3
  libeigen3-dev libsuitesparse-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libopenimageio-dev openimageio-tools libtbb-dev fonts-dejavu-core
  openmpi-bin libopenmpi-dev
  libceres-dev  # isolink compare's fit (analysis/compare_fit.cpp)
  libgtest-dev libgmock-dev libbenchmark-dev ngspice
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module (python/) and its tests
  clang libclang-rt-14-dev  # libFuzzer targets (tests/fuzz) in CI
  clang-format  # the `format` test (tools/check_format.sh)
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# shellcheck disable=SC2086
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${ISOLINK_CMAKE_ARGS:-} >/dev/null
cmake --build build -j"${ISOLINK_JOBS:-2}"
