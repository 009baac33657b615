// A fixed-length run of the production attitude filter for instruction counting (callgrind is
// deterministic and load-independent where Google Benchmark's ns drift with the other core):
//   valgrind --tool=callgrind --toggle-collect='*run_updates*' build/bin/attitude_count [N]
// then divide the Ir total by the updates printed. N: read output() after every Nth update
// (1 = every update, as fusion_bench and eval do, the default; 4 = the boat node's 25 of 100 Hz;
// 0 = never).
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace {

using telltale::fusion::ImuSample;
using telltale::fusion::TelltaleAttitudeFilter;

/// The dinghy stream (120 s at 25 Hz) of fusion_bench, replayed `laps` times; not inlined so
/// callgrind can count exactly this function.
[[gnu::noinline]] double run_updates(TelltaleAttitudeFilter& f, const std::vector<ImuSample>& v,
                                     int laps, int read_every) {
  double sink = 0.0;
  double t_offset = 0.0;
  int n = 0;
  for (int lap = 0; lap < laps; ++lap) {
    for (ImuSample s : v) {
      s.t_s += t_offset;
      f.update(s);
      if (read_every > 0 && ++n == read_every) {
        n = 0;
        sink += f.output().heel_rad;
      }
    }
    t_offset += v.back().t_s + 0.04;
  }
  return sink;
}

}  // namespace

int main(int argc, char** argv) {
  const int read_every = argc > 1 ? std::atoi(argv[1]) : 1;
  std::vector<ImuSample> v;
  auto sc = telltale::fusion::sim::make_scenario("dinghy", 1, 25.0, 120.0);
  ImuSample s;
  telltale::fusion::sim::AttitudeTruth t;
  while (sc->next(s, t)) v.push_back(s);
  constexpr int kLaps = 4;
  TelltaleAttitudeFilter f;
  double sink = run_updates(f, v, kLaps, read_every);
  sink += f.output().heel_rad;
  std::printf("updates %zu sink %.17g\n", v.size() * kLaps, sink);
  return 0;
}
