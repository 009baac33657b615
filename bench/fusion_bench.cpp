// ns per update of every fusion filter: build/bin/fusion_bench
#include <benchmark/benchmark.h>

#include <cmath>

#include "telltale/fusion/complementary.hpp"

namespace {

void BM_Complementary(benchmark::State& state) {
  telltale::fusion::ComplementaryFilter filter;
  telltale::fusion::ImuSample s{0.0, {0.01, -0.02, 0.3}, {0.5, 1.0, 9.7}};
  for (auto _ : state) {
    s.t_s += 0.01;
    filter.update(s);
    benchmark::DoNotOptimize(filter.heel_rad());
  }
}
BENCHMARK(BM_Complementary);

}  // namespace

BENCHMARK_MAIN();
