#!/usr/bin/env bash
# Installs the Debian packages mcslam needs (only those missing) and builds everything into build/.
# Usage: tools/setup.sh            (Release build in ./build, executables in ./build/bin)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config git python3
  libeigen3-dev libopencv-dev libopengv-dev libsuitesparse-dev libspdlog-dev libyaml-cpp-dev libcli11-dev
  libaravis-dev aravis-tools libusb-1.0-0-dev libgpiod-dev
  libgtest-dev libgmock-dev libbenchmark-dev libceres-dev
  systemd ccache
)
source tools/install-packages.sh
install_missing setup "${packages[@]}"
default_to_ninja

jobs="$(nproc)"
# ccache (when installed) makes rebuilds after a checkout or a clean cheap.
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
# MCSLAM_CMAKE_ARGS: extra CMake arguments, after ours (tools/run-tests.sh --ci passes -DMCSLAM_WERROR=ON and
# -DMCSLAM_BUILD_BENCHMARKS=OFF).
# shellcheck disable=SC2086
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMCSLAM_BUILD_BENCHMARKS=ON "${launcher[@]}" ${MCSLAM_CMAKE_ARGS:-}
cmake --build build -j"$jobs"
echo "setup: built; executables are in build/bin"
