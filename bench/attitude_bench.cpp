// ns per update of every attitude filter, on a recorded-like stream (the dinghy simulator).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace {

using telltale::fusion::ImuSample;

const std::vector<ImuSample>& dinghy_samples() {
  static const std::vector<ImuSample> samples = [] {
    std::vector<ImuSample> v;
    auto sc = telltale::fusion::sim::make_scenario("dinghy", 1, 25.0, 120.0);
    ImuSample s;
    telltale::fusion::sim::AttitudeTruth t;
    while (sc->next(s, t)) v.push_back(s);
    return v;
  }();
  return samples;
}

/// Through the registry (virtual call), as fusion_cli runs it.
void BM_AttitudeFilter(benchmark::State& state, const std::string& name) {
  const auto& samples = dinghy_samples();
  auto filter = telltale::fusion::make_attitude_filter(name);
  std::size_t i = 0;
  double t_offset = 0.0;
  for (auto _ : state) {
    ImuSample s = samples[i];
    s.t_s += t_offset;
    filter->update(s);
    benchmark::DoNotOptimize(filter->output().heel_rad);
    if (++i == samples.size()) {
      i = 0;
      t_offset += samples.back().t_s + 0.04;
    }
  }
}

/// The concrete production class, as the boat node holds it (no virtual call); output() read
/// after every kReadEvery-th update (a constant, so reading every update costs no modulo).
template <std::size_t kReadEvery>
void run_concrete(benchmark::State& state) {
  const auto& samples = dinghy_samples();
  telltale::fusion::TelltaleAttitudeFilter filter;
  std::size_t i = 0;
  double t_offset = 0.0;
  for (auto _ : state) {
    ImuSample s = samples[i];
    s.t_s += t_offset;
    filter.update(s);
    if (i % kReadEvery == 0) benchmark::DoNotOptimize(filter.output().heel_rad);
    if (++i == samples.size()) {
      i = 0;
      t_offset += samples.back().t_s + 0.04;
    }
  }
}

/// An output read after every update, as fusion_cli and eval do.
void BM_TelltaleConcrete(benchmark::State& state) { run_concrete<1>(state); }
/// At the boat node's ratio: one output read per 4 updates (100 Hz IMU, published at 25 Hz).
void BM_TelltaleNode(benchmark::State& state) { run_concrete<4>(state); }

int register_all() {
  for (const auto& name : telltale::fusion::attitude_filter_names()) {
    benchmark::RegisterBenchmark(("BM_Attitude/" + name).c_str(),
                                 [name](benchmark::State& st) { BM_AttitudeFilter(st, name); });
  }
  benchmark::RegisterBenchmark("BM_Attitude/telltale_concrete", BM_TelltaleConcrete);
  benchmark::RegisterBenchmark("BM_Attitude/telltale_node", BM_TelltaleNode);
  return 0;
}
const int kRegistered = register_all();

}  // namespace
