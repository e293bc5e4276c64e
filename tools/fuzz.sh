#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang, AddressSanitizer + UBSan) in build-fuzz/ and runs each on a copy of
# its seed corpus (tests/fuzz/corpus/<target>/).
#
# Usage: tools/fuzz.sh [TARGET] [--runs N] [--seconds S] [--ci]
#   TARGET       one target (fuzz_calibration, ...); default: every target
#   --runs N     inputs per target (default 1000000)
#   --seconds S  stop a target after S seconds (whichever of N and S comes first)
#   --ci         only the targets CI runs (those that build from the lower libraries; tests/fuzz/CMakeLists.txt)
# The copy, with what the fuzzer added, its log and its findings stay in build-fuzz/fuzz-work/<target>/.
# Per target it prints the inputs run, the crashes and the time. Exit status 1 when a target crashed, hung, ran out of
# memory or a sanitizer reported; the reproducer's path is printed (run it again: build-fuzz/bin/<target> <file>).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { sed -n '2,/^set /p' "$0" | sed '$d; s/^# \{0,1\}//'; }
runs=1000000
seconds=0
only=""
ci=0
while (($#)); do
  case "$1" in
    --runs) runs="$2"; shift ;;
    --seconds) seconds="$2"; shift ;;
    --ci) ci=1 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "fuzz: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) only="$1" ;;
  esac
  shift
done

# Debian 12's clang and its libFuzzer runtime; the libraries' own dependencies come with tools/setup.sh.
source tools/install-packages.sh
install_missing fuzz clang libclang-rt-14-dev
default_to_ninja

build=build-fuzz
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
# -O1 with line tables, as the sanitizer jobs: reports name the line. No tests or benchmarks: only the targets.
cmake -S . -B "$build" -DMCSLAM_FUZZ=ON -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -g1" -DCMAKE_C_FLAGS_RELEASE="-O1 -g1" \
  -DMCSLAM_BUILD_TESTS=OFF -DMCSLAM_BUILD_BENCHMARKS=OFF "${launcher[@]}" >/dev/null

mapfile -t targets < <(awk -v ci="$ci" -v only="$only" \
  '(only == "" || $1 == only) && (!ci || $2 == "ci") { print $1 }' "$build/fuzz_targets.txt")
if ((${#targets[@]} == 0)); then
  echo "fuzz: no target '$only' (targets: $(cut -d' ' -f1 "$build/fuzz_targets.txt" | tr '\n' ' '))" >&2
  exit 2
fi
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"

failed=0
for t in "${targets[@]}"; do
  work="$build/fuzz-work/$t"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  cp -r "tests/fuzz/corpus/$t/." "$work/corpus/"
  # rss_limit_mb: an input that takes more than 2 GB is a finding (the readers bound what they allocate);
  # timeout: one input taking more than 10 s is a hang. Leaks are findings too (libFuzzer's default).
  args=(-runs="$runs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -artifact_prefix="$work/artifacts/")
  ((seconds > 0)) && args+=(-max_total_time="$seconds")
  start=$(date +%s)
  status=0
  "$build/bin/$t" "${args[@]}" "$work/corpus" >"$work/log" 2>&1 || status=$?
  elapsed=$(($(date +%s) - start))
  inputs=$(grep -oE 'stat::number_of_executed_units: [0-9]+' "$work/log" | grep -oE '[0-9]+$' || true)
  found=$(find "$work/artifacts" -type f | head -1)
  if ((status != 0)) || [ -n "$found" ]; then
    failed=1
    echo "fuzz: $t: ${inputs:-?} inputs, 1 crash, ${elapsed} s: reproducer ${found:-(none written)}, log $work/log"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error)' "$work/log" | head -3 | sed 's/^/fuzz:   /'
  else
    echo "fuzz: $t: ${inputs:-?} inputs, 0 crashes, ${elapsed} s"
  fi
done
exit "$failed"
