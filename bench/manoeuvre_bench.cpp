// Manoeuvres: detection and metrics for a 2 h session of one boat (72 000 fixes at
// 10 Hz from the race simulator with drills, heel at 25 Hz). Target: <= 50 ms.
#include <benchmark/benchmark.h>

#include <algorithm>

#include "telltale/fusion/manoeuvres.hpp"
#include "telltale/fusion/sim/course.hpp"

namespace {

using namespace telltale::fusion;

void BM_Manoeuvres2h(benchmark::State& state) {
  sim::CourseParams p;
  p.drills = true;
  sim::CourseSim course(7, p);
  std::vector<CourseSample> fixes;
  std::vector<HeelSample> heel;
  std::vector<double> heel10;
  for (int k = 0; k < 72000; ++k) {
    const auto s = course.at(k * 0.1);
    fixes.push_back({s.t_s, s.cog_deg, s.sog_m_s});
    heel10.push_back(s.heel_deg);
  }
  for (std::size_t i = 0; i < 180000; ++i) {  // 25 Hz, interpolated between the 10 Hz states
    const double t = static_cast<double>(i) * 0.04;
    const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(t / 0.1), 71998);
    const double f = t / 0.1 - static_cast<double>(k);
    heel.push_back({t, heel10[k] + (heel10[k + 1] - heel10[k]) * f, 1.0});
  }
  std::size_t found = 0;
  for (auto _ : state) {
    const auto rep = analyse_manoeuvres(fixes, heel);
    found = rep.manoeuvres.size();
    benchmark::DoNotOptimize(rep);
  }
  state.counters["manoeuvres"] = static_cast<double>(found);
  state.counters["fixes"] = static_cast<double>(fixes.size());
  state.counters["heel"] = static_cast<double>(heel.size());
}
BENCHMARK(BM_Manoeuvres2h)->Unit(benchmark::kMillisecond);

}  // namespace
