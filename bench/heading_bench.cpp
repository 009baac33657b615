// Time per HeadingFusion::update for N = 3 and N = 8 sensors, every method.
// Readings come from the dinghy scenario (tacks, one sensor at 5 Hz), replayed in a loop so the
// monitor and every fusion branch run as they do on the water.
#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#include "telltale/fusion/heading_fusion.hpp"
#include "telltale/fusion/sim/heading_sim.hpp"

namespace {

using telltale::fusion::HeadingFusion;
using telltale::fusion::HeadingMethod;
using telltale::fusion::kAllHeadingMethods;
using telltale::fusion::kMaxHeadingSensors;

void BM_HeadingUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto method = kAllHeadingMethods[static_cast<std::size_t>(state.range(1))];
  auto sc = *telltale::fusion::sim::heading_scenario("dinghy-spikes");
  sc.sensors.resize(static_cast<std::size_t>(n), sc.sensors[0]);
  sc.fusion.sensor_count = n;
  sc.fusion.method = method;
  const auto samples = telltale::fusion::sim::simulate_heading(sc, 1);
  std::vector<std::array<double, kMaxHeadingSensors>> rows(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    for (int i = 0; i < n; ++i) {
      rows[k][static_cast<std::size_t>(i)] = samples[k].reading_deg[static_cast<std::size_t>(i)];
    }
  }
  HeadingFusion f(sc.fusion);
  std::size_t k = 0;
  double t = 0.0;
  for (auto _ : state) {
    f.update(t, rows[k].data());
    benchmark::DoNotOptimize(f.heading_deg());
    t += 0.1;
    k = (k + 1) % rows.size();
  }
  state.SetLabel(std::string(telltale::fusion::heading_method_name(method)) +
                 " N=" + std::to_string(n));
}

void heading_args(benchmark::internal::Benchmark* b) {
  for (int n : {3, 8}) {
    for (int m = 0; m < static_cast<int>(kAllHeadingMethods.size()); ++m) b->Args({n, m});
  }
}
BENCHMARK(BM_HeadingUpdate)->Apply(heading_args)->Unit(benchmark::kMicrosecond);

}  // namespace
