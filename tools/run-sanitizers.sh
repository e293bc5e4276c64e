#!/usr/bin/env bash
# The sanitizer jobs: AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/) and ThreadSanitizer
# (build-tsan/), at -O1 with line tables (-g1) so that a report names the line.
#
# Usage: tools/run-sanitizers.sh [--full] [address|thread|all]     (default: all; tools/setup.sh must have run once)
#   without --full (what CI runs): the suites labelled sanitizer-ci* (tests/CMakeLists.txt: the code that parses
#                  files, indexes raw memory or owns threads) under ASan+UBSan, and those of them that run
#                  threads and build from the lower stages (sanitizer-ci-threads) under TSan.
#   --full         every suite under ASan+UBSan and every threaded suite under TSan: too long for CI on two cores
#                  (BENCHMARKS.md, "Sanitizers"); run it before resolving an issue that touches the core.
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
which=all
for arg in "$@"; do
  case "$arg" in
    --full) full=1 ;;
    address|thread|all) which="$arg" ;;
    *) echo "run-sanitizers: unknown argument '$arg' (expected --full, address, thread or all)" >&2; exit 2 ;;
  esac
done

source tools/install-packages.sh
default_to_ninja
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
jobs="$(nproc)"

configure() {  # build dir, sanitizer
  cmake -S . -B "$1" -DMCSLAM_SANITIZE="$2" -DMCSLAM_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" -DCMAKE_C_FLAGS_RELEASE="-O1 -g1" "${launcher[@]}" >/dev/null
}

run_job() {  # build dir, sanitizer, CI target (= its ctest label), ctest label filter for --full...
  local dir="$1" sanitizer="$2" target="$3"
  shift 3
  configure "$dir" "$sanitizer"
  if ((full)); then
    cmake --build "$dir" -j"$jobs"
  else
    cmake --build "$dir" -j"$jobs" --target "$target"
    set -- -L "$target"
  fi
  ctest --test-dir "$dir" "$@" --output-on-failure --timeout 1800 -j"$jobs"
}

scope="the CI suites"
((full)) && scope="every suite"
if [ "$which" != thread ]; then
  echo "run-sanitizers: AddressSanitizer + UBSan, $scope (build-asan/)"
  # detect_leaks: every test process must free what it allocated; halt_on_error keeps the first report readable.
  ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
    run_job build-asan address sanitizer-ci
fi
if [ "$which" != address ]; then
  echo "run-sanitizers: ThreadSanitizer, $scope that run threads (build-tsan/)"
  # The suppressions cover uninstrumented libraries only (the file says which and why).
  TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tools/sanitizers/tsan.supp" \
    run_job build-tsan thread sanitizer-ci-threads -L threads
fi
echo "run-sanitizers: clean"
