// The shore's live path, per sample, as the live worker runs it (shore_server/main.cpp): the
// fleet model's update, the hub's publish, and a dashboard frame's JSON (rendered for at most 10
// of a boat's 25 samples a second). Times x 25 000 (1000 boats x 25 Hz) are the share of a core
// a 1000-boat fleet takes on that path.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "fleet.hpp"
#include "json_views.hpp"
#include "live_hub.hpp"

namespace {

using namespace telltale::shore;

constexpr std::uint64_t kStart = std::uint64_t{1'780'000'000} * 1'000'000'000;

/// A boat as the fleet model holds it mid-race: status, a fresh fix.
BoatView sailing_boat() {
  FleetModel fleet(std::chrono::milliseconds(2000));
  NodeStatusInfo st;
  st.kind = "boat";
  st.software_version = "0.9.0";
  st.uptime_s = 3600.0;
  st.group = "ilca7";
  fleet.update_status("bench-042", st);
  AttitudeSample s;
  s.boat_id = "bench-042";
  s.t_utc_ns = kStart;
  s.seq = 90000;
  s.heel_deg = 17.3125;
  s.pitch_deg = -2.0625;
  s.heading_deg = 212.4;
  s.heel_rate_deg_s = 1.5;
  s.pitch_rate_deg_s = -0.25;
  s.yaw_rate_deg_s = 3.1;
  s.accel_weight = 0.82;
  s.quality = 0.97;
  const auto now = std::chrono::steady_clock::now();
  (void)fleet.update(s, now, kStart + 3'000'000);
  FixSample f;
  f.boat_id = s.boat_id;
  f.t_utc_ns = kStart;
  f.gnss_utc_ns = kStart + 40'000'000;
  f.lat_deg = 54.3412345;
  f.lon_deg = 10.1912345;
  f.sog_m_s = 3.2;
  f.cog_deg = 211.0;
  f.fix = "3d";
  f.satellites = 14;
  f.hdop = 0.8;
  (void)fleet.update_fix(f, now);
  return *fleet.boat(s.boat_id);
}

void BM_BoatJson(benchmark::State& state) {
  const BoatView v = sailing_boat();
  for (auto _ : state) benchmark::DoNotOptimize(boat_json(v));
}
BENCHMARK(BM_BoatJson)->Unit(benchmark::kMicrosecond);

/// The live worker's per-sample core for `boats` boats: the fleet model's update and the hub's
/// publish (the frame rendered later, by a stream). The alarms and the manoeuvre tracker it also
/// feeds are apart (BM_ManoeuvreLive10min for the tracker).
void BM_LiveWorkerPerSample(benchmark::State& state) {
  const auto boats = static_cast<int>(state.range(0));
  FleetModel fleet(std::chrono::milliseconds(2000));
  LiveHub hub(8, 256, std::chrono::milliseconds(100));
  std::vector<AttitudeSample> samples(static_cast<std::size_t>(boats));
  for (int b = 0; b < boats; ++b) {
    auto& s = samples[static_cast<std::size_t>(b)];
    s.boat_id = "bench-" + std::to_string(b);
    s.t_utc_ns = kStart;
    s.heading_deg = std::nan("");
  }
  std::size_t k = 0;
  for (auto _ : state) {
    auto& s = samples[k++ % samples.size()];
    s.t_utc_ns += 40'000'000;
    ++s.seq;
    BoatView view = fleet.update(s, std::chrono::steady_clock::now(), s.t_utc_ns);
    hub.publish_sample(s.boat_id, [v = std::move(view)] { return boat_json(v); });
  }
}
BENCHMARK(BM_LiveWorkerPerSample)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
