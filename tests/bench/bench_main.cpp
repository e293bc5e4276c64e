// mcslam_bench entry point. Run: build/bin/mcslam_bench [--benchmark_filter=<regex>]
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
