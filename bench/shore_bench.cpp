// The shore's benchmarks (manoeuvre_live_bench.cpp, live_path_bench.cpp, store_bench.cpp) in one
// program.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
