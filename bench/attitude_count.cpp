// A fixed-length run of the production attitude filter for instruction counting (callgrind is
// deterministic and load-independent where Google Benchmark's ns drift with the other core):
//   valgrind --tool=callgrind --toggle-collect='*run_updates*' build/bin/attitude_count
// then divide the Ir total by the updates printed.
#include <cstdio>
#include <vector>

#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace {

using telltale::fusion::ImuSample;
using telltale::fusion::TelltaleAttitudeFilter;

/// The dinghy stream (120 s at 25 Hz) of fusion_bench, replayed `laps` times; not inlined so
/// callgrind can count exactly this function.
[[gnu::noinline]] double run_updates(TelltaleAttitudeFilter& f, const std::vector<ImuSample>& v,
                                     int laps) {
  double sink = 0.0;
  double t_offset = 0.0;
  for (int lap = 0; lap < laps; ++lap) {
    for (ImuSample s : v) {
      s.t_s += t_offset;
      f.update(s);
      sink += f.output().heel_rad;
    }
    t_offset += v.back().t_s + 0.04;
  }
  return sink;
}

}  // namespace

int main() {
  std::vector<ImuSample> v;
  auto sc = telltale::fusion::sim::make_scenario("dinghy", 1, 25.0, 120.0);
  ImuSample s;
  telltale::fusion::sim::AttitudeTruth t;
  while (sc->next(s, t)) v.push_back(s);
  constexpr int kLaps = 4;
  TelltaleAttitudeFilter f;
  const double sink = run_updates(f, v, kLaps);
  std::printf("updates %zu sink %.17g\n", v.size() * kLaps, sink);
  return 0;
}
