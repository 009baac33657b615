// Load generator: N simulated boats x R Hz into a running shore over real DDS, with SSE clients
// measuring delivery latency (boat write -> SSE event), and the shore's CPU and RSS from /proc.
//
//   build/bin/fleet_load --domain D --shore-url http://127.0.0.1:PORT --token T
//       --shore-pid PID --boats 200 --rate-hz 25 --fix-hz 10 --seconds 300 --sse-clients 1
//
// Prints one JSON object: samples and GNSS fixes written, what the shore committed, latency
// percentiles, shore CPU (% of one core) and peak RSS, and where a loss happened (datagrams the
// kernel dropped on the shore's UDP sockets, samples its store refused).
#include <httplib.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string_view>
#include <thread>
#include <vector>

#include "dds_cli.hpp"
#include "dds_participant.hpp"
#include "shutdown.hpp"
#include "telltalePubSubTypes.h"

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

struct ProcStat {
  double cpu_s = 0;
  long rss_kb = 0;
};

ProcStat read_proc(int pid) {
  ProcStat p;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (std::getline(stat, line)) {
    // Fields after the command name (which may contain spaces) start after the last ')'.
    std::istringstream rest(line.substr(line.rfind(')') + 2));
    std::vector<std::string> f;
    std::string tok;
    while (rest >> tok) f.push_back(tok);
    if (f.size() > 13) {
      const double ticks = static_cast<double>(sysconf(_SC_CLK_TCK));
      p.cpu_s = (std::stod(f[11]) + std::stod(f[12])) / ticks;  // utime + stime
    }
  }
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) p.rss_kb = std::stol(line.substr(6));
  return p;
}

/// Datagrams the kernel dropped on `pid`'s UDP sockets (receive buffer full) since they opened:
/// the samples a busy shore lost before DDS saw them. The sockets are found by inode in /proc/PID/fd, their drop
/// counters in the last column of /proc/PID/net/udp and udp6.
long udp_drops(int pid) {
  std::vector<std::string> inodes;
  std::error_code ec;
  const std::string proc = "/proc/" + std::to_string(pid);
  for (const auto& fd : std::filesystem::directory_iterator(proc + "/fd", ec)) {
    const std::string target = std::filesystem::read_symlink(fd.path(), ec).string();
    if (target.rfind("socket:[", 0) == 0) inodes.push_back(target.substr(8, target.size() - 9));
  }
  long drops = 0;
  for (const char* table : {"/net/udp", "/net/udp6"}) {
    std::ifstream in(proc + table);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream f(line);
      std::vector<std::string> col;
      std::string tok;
      while (f >> tok) col.push_back(tok);
      if (col.size() > 12 && std::find(inodes.begin(), inodes.end(), col[9]) != inodes.end())
        drops += std::stol(col[12]);
    }
  }
  return drops;
}

}  // namespace

int main(int argc, char** argv) {
  telltale::ShutdownSignal shutdown;
  telltale::dds::DdsOptions dds;
  int domain = -1;
  std::string url = "http://127.0.0.1:8080";
  std::string token;
  int shore_pid = 0;
  int boats = 200;
  double rate_hz = 25;
  double fix_hz = 10;
  double seconds = 300;
  int sse_clients = 1;
  CLI::App app{"Telltale fleet load generator"};
  const std::string shore = "Shore";
  app.add_option("--shore-url", url, "shore base URL")->required()->group(shore);
  app.add_option("--token", token, "coach token")->required()->group(shore);
  app.add_option("--shore-pid", shore_pid, "shore process id (CPU and RSS)")->group(shore);

  const std::string load = "Load";
  app.add_option("--boats", boats, "simulated boats")->capture_default_str()->group(load);
  app.add_option("--rate-hz", rate_hz, "attitude samples per boat per second")
      ->capture_default_str()
      ->group(load);
  app.add_option("--fix-hz", fix_hz,
                 "GNSS fixes per boat per second (a divisor of --rate-hz); 0: none")
      ->capture_default_str()
      ->group(load);
  app.add_option("--seconds", seconds, "length of the run")->capture_default_str()->group(load);
  app.add_option("--sse-clients", sse_clients, "SSE clients held open (the first measures latency)")
      ->capture_default_str()
      ->group(load);

  app.add_option("--domain", domain, "DDS domain")->required()->group(telltale::dds::kCliGroup);
  app.add_option("--dds-profiles", dds.profiles_file, "Fast DDS profiles XML")
      ->group(telltale::dds::kCliGroup);
  CLI11_PARSE(app, argc, argv);
  dds.domain = domain;

  std::smatch m;
  if (!std::regex_match(url, m, std::regex(R"(http://([^:/]+):(\d+)/?)"))) {
    std::fprintf(stderr, "fleet_load: --shore-url must be http://HOST:PORT\n");
    return 2;
  }
  const std::string host = m[1];
  const int port = std::stoi(m[2]);

  // SSE clients: the first records latency of every sample event it receives.
  std::atomic<bool> stop{false};
  std::mutex lat_mutex;
  std::vector<double> latencies_ms;
  std::atomic<long> sse_events{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < sse_clients; ++i) {
    clients.emplace_back([&, i] {
      httplib::Client c(host, port);
      c.set_read_timeout(30);
      std::string buf;
      c.Get("/api/v1/stream", {{"Authorization", "Bearer " + token}},
            [&](const char* data, std::size_t len) {
              buf.append(data, len);
              // Frames are cut by offset and the consumed part erased once per chunk: erasing
              // each frame from the front moved the rest of a batch (1000 boats: ~700 KB) once
              // per frame, and the client's own copying showed up as hundreds of ms of latency.
              const double now = static_cast<double>(telltale::utc_now_ns());
              std::size_t begin = 0;
              std::size_t end;
              while ((end = buf.find("\n\n", begin)) != std::string::npos) {
                const std::string_view frame(buf.data() + begin, end - begin);
                begin = end + 2;
                if (i != 0 || frame.rfind("event: sample", 0) != 0) continue;
                const auto pos = frame.find("\"t_utc_ns\":");
                if (pos == std::string_view::npos) continue;
                const double sent = std::strtod(frame.data() + pos + 11, nullptr);
                std::lock_guard lock(lat_mutex);
                latencies_ms.push_back((now - sent) * 1e-6);
                ++sse_events;
              }
              buf.erase(0, begin);
              return !stop.load();
            });
    });
  }

  telltale::dds::Participant participant(dds, "fleet_load");
  auto* writer = participant.writer(
      participant.topic(telltale::dds::kTopicBoatAttitude,
                        eprosima::fastdds::dds::TypeSupport(
                            new telltale::msg::BoatAttitudePubSubType())),
      "attitude_writer");
  auto* fix_writer = participant.writer(
      participant.topic(telltale::dds::kTopicBoatFix,
                        eprosima::fastdds::dds::TypeSupport(new telltale::msg::BoatFixPubSubType())),
      "fix_writer");
  std::this_thread::sleep_for(std::chrono::seconds(3));  // discovery
  // The first seconds of latencies include discovery; count from here.
  {
    std::lock_guard lock(lat_mutex);
    latencies_ms.clear();
  }

  const ProcStat before = shore_pid ? read_proc(shore_pid) : ProcStat{};
  long peak_rss = before.rss_kb;
  std::vector<telltale::msg::BoatAttitude> samples(static_cast<std::size_t>(boats));
  for (int b = 0; b < boats; ++b) {
    char id[32];
    std::snprintf(id, sizeof id, "load-%03d", b);
    samples[static_cast<std::size_t>(b)].boat_id(id);
  }
  std::vector<telltale::msg::BoatFix> fixes(static_cast<std::size_t>(boats));
  for (int b = 0; b < boats; ++b) {
    auto& f = fixes[static_cast<std::size_t>(b)];
    f.boat_id(samples[static_cast<std::size_t>(b)].boat_id());
    f.fix(telltale::msg::FIX_KIND_3D);
    f.satellites(12);
    f.hdop(0.8f);
  }
  // Fixes every `fix_every` attitude ticks (25 / 10 Hz: alternately every 2nd and 3rd tick).
  const double fix_every = fix_hz > 0 ? rate_hz / fix_hz : 0.0;
  double next_fix_tick = 0.0;
  long fixes_written = 0;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz));
  // Drops during discovery are not the load's: count from here.
  const long drops_before = shore_pid ? udp_drops(shore_pid) : 0;
  const auto start = Clock::now();
  auto tick = start;
  long written = 0;
  long failed = 0;
  std::uint64_t seq = 0;
  // Real boats sample on clocks of their own, so a fleet's datagrams arrive spread over each
  // period, not all at once: each tick writes the fleet in kSlices slices spread over the period
  // (one burst of 2000 boats' attitude and fixes is ~4000 datagrams, more than a 4 MB socket
  // buffer holds, and no fleet sends that).
  constexpr std::size_t kSlices = 8;
  while (!shutdown.stop_requested() &&
         std::chrono::duration<double>(Clock::now() - start).count() < seconds) {
    ++seq;
    const bool fix_due = fix_every > 0 && static_cast<double>(seq) >= next_fix_tick;
    if (fix_due) next_fix_tick += fix_every;
    const double t = static_cast<double>(seq) / rate_hz;
    for (std::size_t k = 0; k < kSlices; ++k) {
      const std::size_t lo = k * samples.size() / kSlices;
      const std::size_t hi = (k + 1) * samples.size() / kSlices;
      for (std::size_t b = lo; b < hi; ++b) {
        auto& s = samples[b];
        s.seq(seq);
        s.t_utc_ns(telltale::utc_now_ns());
        s.heel_deg(10.0 * std::sin(static_cast<double>(seq) * 0.05));
        s.pitch_deg(2.0);
        s.heading_deg(std::nan(""));
        if (writer->write(&s)) {
          ++written;
        } else {
          ++failed;
        }
      }
      for (std::size_t b = lo; fix_due && b < hi; ++b) {
        auto& f = fixes[b];
        f.seq(f.seq() + 1);
        f.t_utc_ns(telltale::utc_now_ns());
        f.gnss_utc_ns(f.t_utc_ns());
        // Each boat sails its own circle of 200 m around its own spot, 3 m/s.
        const double a = t * 3.0 / 200.0 + static_cast<double>(b);
        f.lat_deg(54.34 + (static_cast<double>(b % 20) * 300.0 + 200.0 * std::sin(a)) / 111195.0);
        f.lon_deg(10.19 + (static_cast<double>(b / 20) * 300.0 + 200.0 * std::cos(a)) / 65000.0);
        f.sog_m_s(3.0);
        const double cog = std::fmod(-a * 180.0 / M_PI, 360.0);  // clockwise = -a
        f.cog_deg(cog < 0.0 ? cog + 360.0 : cog);
        if (fix_writer->write(&f)) {
          ++fixes_written;
        } else {
          ++failed;
        }
      }
      if (k + 1 < kSlices) std::this_thread::sleep_until(tick + period * (k + 1) / kSlices);
    }
    if (shore_pid && seq % 25 == 0) peak_rss = std::max(peak_rss, read_proc(shore_pid).rss_kb);
    tick += period;
    std::this_thread::sleep_until(tick);
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  const ProcStat after = shore_pid ? read_proc(shore_pid) : ProcStat{};
  std::this_thread::sleep_for(std::chrono::seconds(2));  // let the shore commit
  stop = true;

  httplib::Client c(host, port);
  auto health = c.Get("/healthz");
  const json h = health ? json::parse(health->body, nullptr, false) : json();
  const long committed = h.is_object() ? h.value("samples_committed", -1L) : -1;
  const long fixes_committed = h.is_object() ? h.value("fixes_committed", -1L) : -1;
  const long store_dropped =
      h.is_object() && h.contains("store") ? h["store"].value("dropped", -1L) : -1;
  for (auto& t : clients) t.join();  // each returns on its next event (the shore keeps streaming)

  std::sort(latencies_ms.begin(), latencies_ms.end());
  const auto pct = [&](double p) {
    if (latencies_ms.empty()) return -1.0;
    return latencies_ms[static_cast<std::size_t>(p * static_cast<double>(latencies_ms.size() - 1))];
  };
  json out = {{"boats", boats},
              {"rate_hz", rate_hz},
              {"seconds", elapsed},
              {"samples_written", written},
              {"write_failures", failed},
              {"samples_committed_by_shore", committed},
              {"fix_hz", fix_hz},
              {"fixes_written", fixes_written},
              {"fixes_committed_by_shore", fixes_committed},
              {"sse_clients", sse_clients},
              {"sse_sample_events_measured", sse_events.load()},
              {"latency_ms_p50", pct(0.50)},
              {"latency_ms_p99", pct(0.99)},
              {"latency_ms_max", latencies_ms.empty() ? -1.0 : latencies_ms.back()}};
  if (shore_pid) {
    out["shore_cpu_percent_of_one_core"] = 100.0 * (after.cpu_s - before.cpu_s) / elapsed;
    out["shore_rss_mb_peak"] = static_cast<double>(peak_rss) / 1024.0;
    out["shore_udp_receive_drops"] = udp_drops(shore_pid) - drops_before;
  }
  out["shore_store_dropped"] = store_dropped;
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}
