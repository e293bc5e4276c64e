#!/usr/bin/env bash
# Cross-builds mcslam for arm64 (AArch64) into build-arm64/ with Debian's cross toolchain, against an arm64 root of
# Debian's own -dev packages, and installs what is missing for that (only the missing host packages, like
# tools/setup.sh; the root once). Executables run on this machine through qemu-user (tools/test-arm64.sh).
#
# Usage: tools/build-arm64.sh [TARGET...]        (no target: everything; `arm64-ci`: the subset meant for CI)
#   MCSLAM_ARM64_ROOT   where the arm64 root lives (default ~/.cache/mcslam/arm64-root-bookworm, ~1.3 GB): made with
#                       mmdebstrap (extract variant: the packages unpacked, no foreign code run), remade when the
#                       package list below changes
#   MCSLAM_CMAKE_ARGS   extra CMake arguments (e.g. -DMCSLAM_WERROR=ON)
#   MCSLAM_ARM64_BUILD_DIR  the build folder (default build-arm64; tools/package.sh uses its own)
# Why a root and not multiarch (dpkg --add-architecture arm64): libopencv-dev, libyaml-cpp-dev and OpenCV's and
# Ceres' dependencies are not Multi-Arch: same, so their arm64 -dev packages cannot be installed beside the amd64
# ones tools/setup.sh installs (docs/arm64.md).
set -euo pipefail
cd "$(dirname "$0")/.."

root="${MCSLAM_ARM64_ROOT:-${HOME}/.cache/mcslam/arm64-root-bookworm}"
host_packages=(cmake ninja-build pkg-config ccache file g++-aarch64-linux-gnu qemu-user-static mmdebstrap)
# tools/setup.sh's libraries, for arm64; libc6-dev and libstdc++-12-dev so that the root is a complete sysroot.
root_packages=(
  libc6-dev libstdc++-12-dev
  libeigen3-dev libopencv-dev libopengv-dev libsuitesparse-dev libspdlog-dev libyaml-cpp-dev libcli11-dev
  libaravis-dev libusb-1.0-0-dev libgpiod-dev
  libgtest-dev libgmock-dev libbenchmark-dev libceres-dev
)

source tools/install-packages.sh
install_missing build-arm64 "${host_packages[@]}"
default_to_ninja

stamp="bookworm arm64 ${root_packages[*]}"
if [ "$(cat "$root/.mcslam-root" 2>/dev/null)" != "$stamp" ]; then
  echo "build-arm64: making the arm64 root in $root (downloads ~500 MB)"
  mkdir -p "$(dirname "$root")"
  rm -rf "$root.tmp"
  sources="$(mktemp)"
  cat >"$sources" <<'EOF'
deb http://deb.debian.org/debian bookworm main
deb http://deb.debian.org/debian bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
  # extract: unpacked, not configured, so no arm64 maintainer script has to run (no binfmt_misc needed); the
  # sysroot needs only the files. Not root: mmdebstrap's unshare mode (user namespaces).
  mode=root
  [ "$(id -u)" -eq 0 ] || mode=unshare
  mmdebstrap --variant=extract --arch=arm64 --mode="$mode" --include="$(IFS=,; echo "${root_packages[*]}")" \
    bookworm "$root.tmp" "$sources"
  rm -f "$sources"
  # Absolute links (the -dev .so links to /lib/..., /etc/alternatives) would point into this machine's own
  # files: made relative, inside the root.
  while IFS= read -r -d '' link; do
    ln -sfnr "$root.tmp$(readlink "$link")" "$link"
  done < <(find "$root.tmp" -type l -lname '/*' -print0)
  # update-alternatives never ran: the reference BLAS and LAPACK take the names their users link to.
  lib="$root.tmp/usr/lib/aarch64-linux-gnu"
  for alt in blas lapack; do
    for f in "$lib/$alt"/lib*.so*; do
      [ -e "$lib/$(basename "$f")" ] || ln -s "$alt/$(basename "$f")" "$lib/$(basename "$f")"
    done
  done
  rm -rf "$root"
  mv "$root.tmp" "$root"
  echo "$stamp" >"$root/.mcslam-root"
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
targets=()
for t in "$@"; do targets+=(--target "$t"); done
build="${MCSLAM_ARM64_BUILD_DIR:-build-arm64}"
# shellcheck disable=SC2086
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_TOOLCHAIN_FILE="$PWD/cmake/aarch64-linux-gnu.cmake" \
  -DMCSLAM_ARM64_ROOT="$root" "${launcher[@]}" ${MCSLAM_CMAKE_ARGS:-}
cmake --build "$build" -j"$(nproc)" "${targets[@]}"
echo "build-arm64: built in $build/ (run the tests with tools/test-arm64.sh)"
if [ -e "$build/bin/mcslamd" ]; then file "$build/bin/mcslamd"; fi
