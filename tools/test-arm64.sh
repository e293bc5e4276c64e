#!/usr/bin/env bash
# Runs the tests of the arm64 cross build (build-arm64/, made by tools/build-arm64.sh) under qemu-user, through
# CTest: the build's emulator (qemu-aarch64-static -L <arm64 root>) runs every test executable, and the tests that
# start the tools run them through the build's bin-emulated/ scripts.
#
# Usage: tools/test-arm64.sh [--subset] [--build] [CTEST_ARGS...]
#   (default)  the whole suite: needs the whole cross build (tools/build-arm64.sh); several hours under emulation
#              on two cores (docs/arm64.md)
#   --subset   the suites labelled arm64-ci (tests/CMakeLists.txt): the cross-architecture equality tests of the SIMD
#              kernels and the unit suites of the lower stages; what CI runs, needs `tools/build-arm64.sh arm64-ci`
#   --build    runs tools/build-arm64.sh first (only its arm64-ci target with --subset)
# qemu's timings say nothing about the speed on an arm64 board.
set -euo pipefail
cd "$(dirname "$0")/.."
subset=0
build=0
ctest_args=()
for arg in "$@"; do
  case "$arg" in
    --subset) subset=1 ;;
    --build) build=1 ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) ctest_args+=("$arg") ;;
  esac
done

if ((build)); then
  if ((subset)); then tools/build-arm64.sh arm64-ci; else tools/build-arm64.sh; fi
fi
if [ ! -f build-arm64/CTestTestfile.cmake ]; then
  echo "test-arm64: no cross build in build-arm64/ (run tools/build-arm64.sh, or this with --build)" >&2
  exit 2
fi
((subset)) && ctest_args=(-L arm64-ci "${ctest_args[@]}")
# qemu-user does not translate the memory-mapped rings of packet sockets: Aravis, which takes one when it may
# (CAP_NET_RAW, as root), then receives no image. Without the capability it takes its standard UDP socket, which
# qemu passes through. On an arm64 board the packet socket works as on x86-64.
no_packet_socket=()
if [ "$(id -u)" = 0 ] && command -v setpriv > /dev/null; then
  no_packet_socket=(setpriv --inh-caps -net_raw --bounding-set -net_raw)
  if ! "${no_packet_socket[@]}" true 2> /dev/null; then
    echo "test-arm64: cannot drop CAP_NET_RAW (setpriv failed): the fake GigE camera test will receive no image" >&2
    no_packet_socket=()
  fi
fi
"${no_packet_socket[@]}" ctest --test-dir build-arm64 --output-on-failure --timeout 3000 -j"$(nproc)" "${ctest_args[@]}"
