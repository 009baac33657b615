// The store's writer as the live shore runs it: one commit interval (250 ms, the default, or 1 s)
// of every boat's attitude (25 Hz) and GNSS fixes (10 Hz) queued, then committed (Store::flush
// waits for the writer thread's turn) into a real SQLite file that grows from iteration to
// iteration. The time is the process's CPU time, queueing plus the writer's commit (not its
// waiting), so time per iteration over the window is the share of a core that recording the
// fleet takes.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>

#include "store.hpp"

namespace {

using namespace telltale::shore;

double process_cpu_s() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

constexpr std::uint64_t kStart = std::uint64_t{1'780'000'000} * 1'000'000'000;

void BM_StoreCommit(benchmark::State& state) {
  const auto boats = static_cast<int>(state.range(0));
  const auto window_ms = static_cast<int>(state.range(1));  // the commit interval
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("store_bench." + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    StoreConfig config;
    config.path = (dir / "bench.db").string();
    config.commit_interval = std::chrono::milliseconds(window_ms);
    Store store(config);
    std::vector<AttitudeSample> samples(static_cast<std::size_t>(boats));
    std::vector<FixSample> fixes(static_cast<std::size_t>(boats));
    for (int b = 0; b < boats; ++b) {
      auto& s = samples[static_cast<std::size_t>(b)];
      s.boat_id = "bench-" + std::to_string(b);
      s.boot_id = 0x5eed0000u + static_cast<std::uint64_t>(b);
      s.t_utc_ns = kStart + static_cast<std::uint64_t>(b) * 1'000'000;
      s.heading_deg = 100.0;
      auto& f = fixes[static_cast<std::size_t>(b)];
      f.boat_id = s.boat_id;
      f.boot_id = s.boot_id;
      f.t_utc_ns = s.t_utc_ns;
      f.lat_deg = 54.3;
      f.lon_deg = 10.2;
      f.sog_m_s = 3.0;
      f.cog_deg = 200.0;
      f.fix = "3d";
      f.satellites = 12;
      f.hdop = 0.9;
    }
    std::int64_t stored = 0;
    int tick = 0;
    for (auto _ : state) {
      const double cpu0 = process_cpu_s();
      // 25 Hz and 10 Hz over the window, the fractions spread over the iterations
      const int per_boat = (tick + 1) * window_ms / 40 - tick * window_ms / 40;
      const int fixes_per_boat = (tick + 1) * window_ms / 100 - tick * window_ms / 100;
      ++tick;
      for (int k = 0; k < per_boat; ++k) {
        for (auto& s : samples) {
          s.t_utc_ns += 40'000'000;
          ++s.seq;
          s.heel_deg = 15.0 + 5.0 * std::sin(0.1 * static_cast<double>(s.seq));
          s.pitch_deg = -2.0 + std::cos(0.07 * static_cast<double>(s.seq));
          store.enqueue(s);
          ++stored;
        }
      }
      for (int k = 0; k < fixes_per_boat; ++k)
        for (auto& f : fixes) {
          f.t_utc_ns += 100'000'000;
          ++f.seq;
          store.enqueue(f);
        }
      store.flush();
      state.SetIterationTime(process_cpu_s() - cpu0);
    }
    state.counters["samples"] = static_cast<double>(stored);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_StoreCommit)
    ->Args({1000, 250})
    ->Args({1000, 1000})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
