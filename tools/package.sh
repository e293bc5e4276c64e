#!/usr/bin/env bash
# Builds the Debian package of mcslam (mcslamd, the tools, the image codec module, the consumer's headers with their
# CMake package config, the systemd unit, /etc/mcslamd/mcslamd.yaml, the documentation, a manual page per program)
# for amd64 or arm64, into dist/mcslam_<version>_<arch>.deb. amd64 builds natively in build-package-amd64/ (after
# tools/setup.sh's packages); arm64 cross-builds in build-package-arm64/ with tools/build-arm64.sh's toolchain and
# arm64 root. Lists the package's contents and runs lintian when it is installed. What the package does:
# docs/package.md.
#
# Usage: tools/package.sh [amd64|arm64]        (default: this machine's architecture)
set -euo pipefail
cd "$(dirname "$0")/.."

arch="${1:-$(dpkg --print-architecture)}"
case "$arch" in
  amd64 | arm64) ;;
  *) echo "package: architecture '$arch': expected amd64 or arm64" >&2; exit 2 ;;
esac
package_args="-DCMAKE_INSTALL_PREFIX=/usr -DMCSLAM_PACKAGE=ON -DMCSLAM_DEB_ARCHITECTURE=$arch \
-DMCSLAM_BUILD_TESTS=OFF -DMCSLAM_BUILD_BENCHMARKS=OFF"
build="build-package-$arch"
source tools/install-packages.sh
install_missing package help2man  # the manual pages, made from the programs' --help at build time
default_to_ninja
if [ "$arch" = arm64 ]; then
  # The multiarch library folder, as the native build's GNUInstallDirs picks on Debian (a cross build does not).
  package_args="$package_args -DCMAKE_INSTALL_LIBDIR=lib/aarch64-linux-gnu"
  MCSLAM_ARM64_BUILD_DIR="$build" MCSLAM_CMAKE_ARGS="$package_args ${MCSLAM_CMAKE_ARGS:-}" tools/build-arm64.sh
else
  install_missing package cmake g++ pkg-config dpkg-dev
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  # shellcheck disable=SC2086
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" $package_args ${MCSLAM_CMAKE_ARGS:-}
  cmake --build "$build" -j"$(nproc)"
fi
mkdir -p dist
cpack --config "$build/CPackConfig.cmake" -B "$PWD/dist" >/dev/null
rm -rf dist/_CPack_Packages
deb="$(ls -t dist/mcslam_*_"$arch".deb | head -n 1)"
echo "package: $deb"
dpkg-deb --field "$deb"
dpkg-deb --contents "$deb" | awk '{print $6}'
if command -v lintian >/dev/null; then
  lintian --no-tag-display-limit "$deb" || true
fi
