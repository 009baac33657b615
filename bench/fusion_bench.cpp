// ns per update of every fusion filter: build/bin/fusion_bench (each area adds <area>_bench.cpp).
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
