#!/usr/bin/env bash
# Sets up (packages + build) and runs the whole test suite through CTest.
# Usage: tools/run-tests.sh [--ci]
#   --ci   what CI runs (.ci/run): the build with -Werror (no benchmarks), the suite, the formatter check
#          (tools/check-format.sh), the sanitizer jobs (tools/run-sanitizers.sh: ASan+UBSan over the suite, TSan over the threaded tests),
#          a short run of the fuzz targets that build from the lower libraries (tools/fuzz.sh --ci), and the arm64
#          job: the cross build of the arm64-ci suites with -Werror and those suites under qemu-user
#          (tools/build-arm64.sh, tools/test-arm64.sh --subset; docs/arm64.md)
set -euo pipefail
cd "$(dirname "$0")/.."
ci=0
case "${1:-}" in
  "") ;;
  --ci) ci=1 ;;
  -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "run-tests: unknown option '$1' (see --help)" >&2; exit 2 ;;
esac

# Each step says how long it took, so that a CI log shows where its time went (CI has 45 minutes, README).
step() {
  local start=$SECONDS
  "$@"
  echo "run-tests: $1 took $((SECONDS - start)) s"
}

if ((ci)); then
  step tools/check-format.sh  # first: it takes seconds, the rest half an hour
  # Without the benchmarks (half a minute of CI's time): tools/setup.sh builds them.
  MCSLAM_CMAKE_ARGS="-DMCSLAM_WERROR=ON -DMCSLAM_BUILD_BENCHMARKS=OFF" step tools/setup.sh
else
  tools/setup.sh
fi
step ctest --test-dir build --output-on-failure --timeout 900 -j"$(nproc)"
if ((ci)); then
  step tools/run-sanitizers.sh all
  step tools/fuzz.sh --ci --runs 5000  # under 2 minutes on two idle cores, the build included (BENCHMARKS.md, "Fuzzing")
  # About 7 minutes on two idle cores from a cold cache, with the arm64 root's download (docs/arm64.md).
  MCSLAM_CMAKE_ARGS="-DMCSLAM_WERROR=ON" step tools/build-arm64.sh arm64-ci
  step tools/test-arm64.sh --subset
  echo "run-tests: CI's jobs took $SECONDS s in all"
fi
