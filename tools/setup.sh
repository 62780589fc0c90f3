#!/usr/bin/env bash
# Installs isolink's Debian 12 dependencies (when missing), builds into ./build and installs
# bin/isolink and the Python module under /usr/local (`cmake --install build`), where
# /usr/bin/python3 finds `import isolink` with nothing set (python/README.md).
#   bash tools/setup.sh                      # Release build
#   ISOLINK_CMAKE_ARGS="-DISOLINK_WERROR=ON" bash tools/setup.sh
#   ISOLINK_PREFIX=/opt/isolink bash tools/setup.sh   # another prefix; ISOLINK_PREFIX= skips it
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ccache pkg-config python3
  libeigen3-dev libsuitesparse-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libopenimageio-dev openimageio-tools libtbb-dev fonts-dejavu-core
  libopenblas-dev  # LAPACK and BLAS for the reduced model's dense algebra (solver/dense_lapack.h)
  openmpi-bin libopenmpi-dev
  libceres-dev  # isolink compare's fit (analysis/compare_fit.cpp)
  libgtest-dev libgmock-dev libbenchmark-dev ngspice
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module (python/) and its tests
  clang libclang-rt-14-dev  # libFuzzer targets (tests/fuzz) in CI
  clang-format  # the `format` test (tools/check_format.sh)
  libjs-dygraphs  # report.html's plots, inlined at build time (reports/html_report.h)
  chromium  # report.html in a headless browser (tests/reports/html_browser_test.py)
)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# shellcheck disable=SC2086
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${ISOLINK_CMAKE_ARGS:-} >/dev/null
cmake --build build -j"${ISOLINK_JOBS:-2}"
prefix=${ISOLINK_PREFIX-/usr/local}
if [ -n "$prefix" ]; then
  inst=$SUDO
  [ -w "$prefix" ] && inst=""
  $inst cmake --install build --prefix "$prefix" >/dev/null
  echo "setup: installed $prefix/bin/isolink and the Python module (import isolink)"
fi
