// ns per sample of the step detectors and the PDR: build/bin/fusion_bench --benchmark_filter=Steps
#include <benchmark/benchmark.h>

#include <string>

#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/steps.hpp"

namespace {

namespace tf = telltale::fusion;

const tf::sim::GaitRun& walk() {
  static const tf::sim::GaitRun run = tf::sim::simulate_gait(
      *tf::sim::make_gait_scenario("phone-switch", 1), tf::sim::random_person(1), 1);
  return run;
}

void BM_StepsDetector(benchmark::State& state, const std::string& name, tf::StepMount mount) {
  const auto& run = walk();
  auto d = tf::make_step_detector(name, mount);
  tf::StepEvent ev;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(d->update(run.samples[i].imu, ev));
    if (++i == run.samples.size()) {
      i = 0;
      d->reset();
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK_CAPTURE(BM_StepsDetector, adaptive_foot, std::string("adaptive"), tf::StepMount::kFoot);
BENCHMARK_CAPTURE(BM_StepsDetector, adaptive_body, std::string("adaptive"), tf::StepMount::kBody);
BENCHMARK_CAPTURE(BM_StepsDetector, peak, std::string("peak"), tf::StepMount::kBody);
BENCHMARK_CAPTURE(BM_StepsDetector, fixed_threshold, std::string("fixed-threshold"),
                  tf::StepMount::kBody);
BENCHMARK_CAPTURE(BM_StepsDetector, peak_valley, std::string("peak-valley"), tf::StepMount::kBody);

void BM_StepsPdr(benchmark::State& state) {
  const auto& run = walk();
  auto pdr = std::make_unique<tf::Pdr>();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(pdr->update(run.samples[i].imu, run.samples[i].mag_uT).x_m);
    if (++i == run.samples.size()) {
      state.PauseTiming();
      i = 0;
      pdr = std::make_unique<tf::Pdr>();
      state.ResumeTiming();
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_StepsPdr);

}  // namespace
