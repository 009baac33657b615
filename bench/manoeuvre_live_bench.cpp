// Live manoeuvres: the shore's tracker (shore_server/manoeuvre_live.hpp) fed one boat's race
// sample by sample, 10 Hz fixes and 25 Hz attitude, as the live worker feeds it. The time per
// iteration over the seconds of data it holds is the CPU one boat costs per second sailed;
// x 1000 the share of a core a 1000-boat fleet takes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "manoeuvre_live.hpp"
#include "telltale/fusion/sim/course.hpp"

namespace {

using namespace telltale;

constexpr double kSeconds = 600.0;

void BM_ManoeuvreLive10min(benchmark::State& state) {
  fusion::sim::CourseSim course(7, {});
  std::vector<shore::FixSample> fixes;
  std::vector<shore::AttitudeSample> attitude;
  std::vector<double> heel10;
  const std::uint64_t start = std::uint64_t{1'780'000'000} * 1'000'000'000;
  const int n = static_cast<int>(kSeconds * 10);
  for (int k = 0; k < n; ++k) {
    const auto s = course.at(k * 0.1);
    shore::FixSample f;
    f.boat_id = "bench";
    f.t_utc_ns = start + static_cast<std::uint64_t>(k) * std::uint64_t{100'000'000};
    f.cog_deg = s.cog_deg;
    f.sog_m_s = s.sog_m_s;
    fixes.push_back(f);
    heel10.push_back(s.heel_deg);
  }
  for (int i = 0; i * 0.04 < (n - 1) * 0.1; ++i) {
    const double t = i * 0.04;
    const auto k = static_cast<std::size_t>(std::min(t / 0.1, n - 2.0));
    shore::AttitudeSample a;
    a.boat_id = "bench";
    a.t_utc_ns = start + static_cast<std::uint64_t>(i) * std::uint64_t{40'000'000};
    a.heel_deg = heel10[k] + (heel10[k + 1] - heel10[k]) * (t / 0.1 - static_cast<double>(k));
    a.pitch_deg = 1.0;
    attitude.push_back(a);
  }
  std::size_t reported = 0, runs = 0;
  for (auto _ : state) {
    reported = 0;
    shore::ManoeuvreTracker tracker([&](const shore::LiveManoeuvre&) { ++reported; });
    std::size_t f = 0;
    for (const auto& a : attitude) {
      while (f < fixes.size() && fixes[f].t_utc_ns <= a.t_utc_ns) tracker.on_fix(fixes[f++]);
      tracker.on_attitude(a);
    }
    runs = tracker.runs();
  }
  state.counters["reported"] = static_cast<double>(reported);
  state.counters["runs"] = static_cast<double>(runs);
  state.counters["data_s"] = kSeconds;
  // CPU per second of data, and the share of one core 1000 such boats take.
  state.counters["cpu_per_data_s"] = benchmark::Counter(
      kSeconds, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["cores_1000_boats"] = benchmark::Counter(
      kSeconds / 1000.0,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ManoeuvreLive10min)->Unit(benchmark::kMillisecond);

}  // namespace

