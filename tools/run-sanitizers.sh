#!/usr/bin/env bash
# The sanitizer jobs of CI: AddressSanitizer + UndefinedBehaviorSanitizer over the whole test suite (build-asan/)
# and ThreadSanitizer over the tests that run threads (label `threads`, build-tsan/). Both build at -O1 with
# assertions on and line tables (-g1), so that a report names the line.
#
# Usage: tools/run-sanitizers.sh [address|thread|all]     (default: all; tools/setup.sh must have run once)
set -euo pipefail
cd "$(dirname "$0")/.."
which="${1:-all}"
case "$which" in address|thread|all) ;; *) echo "run-sanitizers: expected address, thread or all" >&2; exit 2 ;; esac

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
jobs="$(nproc)"

configure() {  # build dir, sanitizer
  cmake -S . -B "$1" -DMCSLAM_SANITIZE="$2" -DMCSLAM_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" -DCMAKE_C_FLAGS_RELEASE="-O1 -g1" "${launcher[@]}" >/dev/null
}

if [ "$which" != thread ]; then
  echo "run-sanitizers: AddressSanitizer + UBSan, whole suite (build-asan/)"
  configure build-asan address
  cmake --build build-asan -j"$jobs"
  # detect_leaks: every test process must free what it allocated; halt_on_error keeps the first report readable.
  ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure --timeout 1800 -j"$jobs"
fi
if [ "$which" != address ]; then
  echo "run-sanitizers: ThreadSanitizer, threaded tests (build-tsan/)"
  configure build-tsan thread
  cmake --build build-tsan -j"$jobs"
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
    ctest --test-dir build-tsan -L threads --output-on-failure --timeout 1800 -j"$jobs"
fi
echo "run-sanitizers: clean"
