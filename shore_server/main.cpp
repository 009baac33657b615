// shore_server: subscribes to the fleet over DDS, records it, serves the REST API, the live
// stream and the dashboard.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "alarm_service.hpp"
#include "auth.hpp"
#include "dds_cli.hpp"
#include "fleet.hpp"
#include "http_api.hpp"
#include "json_views.hpp"
#include "live_hub.hpp"
#include "manoeuvre_live.hpp"
#include "query.hpp"
#include "shore_dds.hpp"
#include "shutdown.hpp"
#include "store.hpp"

namespace {

using namespace telltale::shore;

bool valid_boat(const std::string& id) { return valid_id(id); }

struct Options {
  telltale::dds::DdsOptions dds;
  HttpConfig http;
  StoreConfig store{""};  ///< empty: default_db_path()
  std::string coach_token;
  std::vector<std::string> analyst_tokens;
  std::vector<std::string> athlete_tokens;  ///< BOAT_ID:TOKEN
  int stale_ms = 2000;
  int commit_ms = 250;
  int session_gap_s = 60;
  int stream_interval_ms = 100;
  int forget_after_s = 6 * 3600;
};

/// Live samples from the DDS listener to the live worker (fleet model, alarms, dashboards).
class LiveQueue {
 public:
  void push(const AttitudeSample& s, std::uint64_t arrival_utc_ns) {
    bool was_empty = false;
    {
      std::lock_guard lock(mutex_);
      // 5 s of a 1000-boat fleet at 25 Hz: beyond that the live view skips ahead (the
      // recording has its own queue and loses nothing).
      if (queue_.size() >= 125000) queue_.clear();
      was_empty = queue_.empty();
      queue_.emplace_back(s, arrival_utc_ns);
    }
    // Only the first sample of a batch wakes the worker: a wake-up per sample (25 000 a second
    // for 1000 boats) cost the receive thread a futex call each and the worker a context switch.
    if (was_empty) cv_.notify_one();
  }
  /// Swaps out everything queued; false once closed. Takes at most every kCoalesce, so the
  /// worker wakes for a batch of samples, not for each (the dashboards take 10 frames a second);
  /// with nothing queued, returns an empty batch after `idle` (the worker's other inputs).
  bool take(std::vector<std::pair<AttitudeSample, std::uint64_t>>& out,
            std::chrono::milliseconds idle) {
    out.clear();
    std::unique_lock lock(mutex_);
    cv_.wait_until(lock, last_take_ + kCoalesce, [&] { return closed_; });
    cv_.wait_for(lock, idle, [&] { return closed_ || !queue_.empty(); });
    if (closed_) return false;
    out.swap(queue_);
    last_take_ = std::chrono::steady_clock::now();
    return true;
  }
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    cv_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  static constexpr std::chrono::milliseconds kCoalesce{5};
  std::vector<std::pair<AttitudeSample, std::uint64_t>> queue_;
  std::chrono::steady_clock::time_point last_take_{};
  bool closed_ = false;
};

/// Stops a worker thread (the `stop` callback makes it return) and joins it when the scope ends.
class JoinOnExit {
 public:
  JoinOnExit(std::thread& thread, std::function<void()> stop)
      : thread_(thread), stop_(std::move(stop)) {}
  ~JoinOnExit() { finish(); }
  /// Stops and joins now (once; later calls and the destructor do nothing).
  void finish() {
    if (!thread_.joinable()) return;
    stop_();
    thread_.join();
  }
  JoinOnExit(const JoinOnExit&) = delete;
  JoinOnExit& operator=(const JoinOnExit&) = delete;

 private:
  std::thread& thread_;
  std::function<void()> stop_;
};

void add_tokens(const Options& o, TokenStore& tokens) {
  tokens.add(o.coach_token, {Role::kCoach, ""});
  for (const auto& t : o.analyst_tokens) tokens.add(t, {Role::kAnalyst, ""});
  for (const auto& bt : o.athlete_tokens) {
    const auto colon = bt.find(':');
    if (colon == std::string::npos || !valid_boat(bt.substr(0, colon)) || colon + 1 >= bt.size())
      throw std::invalid_argument("--athlete-token takes BOAT_ID:TOKEN, got '" + bt + "'");
    tokens.add(bt.substr(colon + 1), {Role::kAthlete, bt.substr(0, colon)});
  }
}

/// The database when --db is not given: $XDG_DATA_HOME/telltale/telltale.db, else
/// ~/.local/share/telltale/telltale.db (the folder created), else ./telltale.db without a home.
std::string default_db_path() {
  std::filesystem::path dir;
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg && *xdg == '/') {
    dir = std::filesystem::path(xdg) / "telltale";
  } else if (const char* home = std::getenv("HOME"); home && *home == '/') {
    dir = std::filesystem::path(home) / ".local" / "share" / "telltale";
  } else {
    return "telltale.db";
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  return (dir / "telltale.db").string();
}

void run(Options o, telltale::ShutdownSignal& shutdown) {
  // The domain (flag or TELLTALE_DOMAIN) is checked before the database is touched: a bad setting
  // is one error line, not a database folder created or a database migrated on the way to it.
  o.dds.domain = telltale::dds::resolve_domain(o.dds.domain);
  if (o.store.path.empty()) o.store.path = default_db_path();
  TokenStore tokens;
  if (o.coach_token.empty()) {
    if (const char* env = std::getenv("TELLTALE_COACH_TOKEN"); env && *env) o.coach_token = env;
  }
  const bool generated_token = o.coach_token.empty();
  if (generated_token) {
    o.coach_token = random_token();
    std::printf("shore_server coach token (generated): %s\n", o.coach_token.c_str());
  }
  add_tokens(o, tokens);

  o.store.commit_interval = std::chrono::milliseconds(o.commit_ms);
  o.store.session_gap = std::chrono::seconds(o.session_gap_s);
  Store store(o.store);
  FleetModel fleet(std::chrono::milliseconds(o.stale_ms));
  LiveHub hub(o.http.max_stream_clients, 256, std::chrono::milliseconds(o.stream_interval_ms));
  AlarmService alarms(store, hub, fleet);
  ManoeuvreLive manoeuvres(hub, fleet, o.session_gap_s);

  // Fast DDS calls the listener on its receive thread: it only queues, so reception never waits
  // for the fleet model, the alarms or the dashboards. The recording is queued first; the live
  // path runs on a worker of its own and, if it ever falls 5 s behind, skips to the newest.
  LiveQueue live;
  // Joined on every way out of run(), the exceptions of the setup below included (a DDS domain
  // that cannot be joined, a port in use): a joinable std::thread destroyed by the unwinding
  // would end the process in std::terminate instead of the one error line main prints.
  std::thread live_worker;
  JoinOnExit live_join{live_worker, [&] { live.close(); }};
  live_worker = std::thread([&] {
    std::vector<std::pair<AttitudeSample, std::uint64_t>> batch;
    while (live.take(batch, ManoeuvreLive::kFixWakeup)) {
      manoeuvres.take_fixes();
      for (const auto& [s, arrival_utc] : batch) {
        BoatView view = fleet.update(s, std::chrono::steady_clock::now(), arrival_utc);
        alarms.on_sample(s, view.status ? view.status->group : std::string());
        hub.publish_sample(s.boat_id, [v = std::move(view)] { return boat_json(v); });
        manoeuvres.on_attitude(s);
      }
    }
  });
  FleetCallbacks callbacks;
  callbacks.on_attitude = [&](const AttitudeSample& s) {
    store.enqueue(s);
    live.push(s, telltale::utc_now_ns());
  };
  callbacks.on_backfill = [&](const AttitudeSample& s) {
    // Old samples go to the recording only: the live view and the alarms are about now.
    store.enqueue(s);
  };
  callbacks.on_wearable = [&](const WearableSample& w) {
    const AthleteView view = fleet.update(w, std::chrono::steady_clock::now());
    store.enqueue(w);
    hub.publish_event("wearable", to_json_text(athlete_object(view)), w.athlete_id);
  };
  callbacks.on_fix = [&](const FixSample& f) {
    // The dashboards get the position with the boat's next attitude frame (25 Hz): a frame of
    // its own per fix would only add load (and carry the previous attitude's time).
    store.enqueue(f);
    // Queued for the manoeuvres, which the live worker finds, never this receive thread.
    if (fleet.update_fix(f, std::chrono::steady_clock::now())) manoeuvres.queue_fix(f);
  };
  // A live boat's wind instrument: recorded, and the boat's manoeuvres classified against it.
  callbacks.on_wind = [&](const WindSample& w) {
    store.enqueue(w);
    manoeuvres.queue_wind(w);
  };
  // Fixes resent from a boat's log: the recording only, as backfilled attitude.
  callbacks.on_fix_backfill = [&](const FixSample& f) { store.enqueue(f); };
  callbacks.on_status = [&](const std::string& id, const NodeStatusInfo& st) {
    fleet.update_status(id, st);
  };
  // Every boat and wearable joins the shore: it announces itself again after each newcomer, who
  // may have missed its first answer (join_announcer.hpp).
  o.dds.announce_on_join = true;
  ShoreDds dds(o.dds, callbacks);
  alarms.start({[&](const std::vector<AlarmRule>& rules) { dds.publish_rules(rules); },
                [&](const AlarmEvent& e) { dds.publish_event(e); }});

  HttpApi api(o.http, {fleet, hub, tokens, store, alarms, &dds.ingest_counters()});
  const int port = api.bind();
  std::thread http_thread;
  JoinOnExit http_join{http_thread, [&] {
                         hub.close();
                         api.stop();
                       }};
  http_thread = std::thread([&] { api.serve(); });
  std::printf("shore_server ready: http://%s:%d/ domain=%d db=%s dds_security=%s\n",
              o.http.bind_address.c_str(), port, dds.domain(), o.store.path.c_str(),
              dds.secured() ? "on" : "off");
  // The link that logs a browser in (the token is exchanged for a cookie and leaves the address
  // bar): printed when the token was generated here, so a first run is one click from the map.
  if (generated_token)
    std::printf("shore_server dashboard: http://%s:%d/#token=%s&view=map\n",
                o.http.bind_address == "0.0.0.0" ? "127.0.0.1" : o.http.bind_address.c_str(), port,
                o.coach_token.c_str());
  std::fflush(stdout);

  // Stale sweep: a boat silent for stale_ms is marked stale (the shore's own clock, no DDS
  // deadline: Fast DDS pays for a deadline per instance on every sample). Each boat
  // gets its receipt (what is stored), from which it backfills what is missing: as soon as it
  // moves (a stopping boat waits for it), and every second anyway (receipts are best effort).
  int tick = 0;
  std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> receipt_sent;  // (boat, run)
  std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> fix_receipt_sent;
  while (!shutdown.wait_for(std::chrono::milliseconds(200))) {
    for (const auto& v : fleet.sweep(std::chrono::steady_clock::now()))
      hub.publish_sample(v.last.boat_id, [v] { return boat_json(v); });
    for (const auto& a : fleet.sweep_athletes(std::chrono::steady_clock::now()))
      hub.publish_event("wearable", to_json_text(athlete_object(a)), a.last.athlete_id);
    const bool repeat = ++tick % 5 == 0;
    // The fixes' receipts go the same way as the attitude's, on their own topic.
    const auto send_receipts = [&](const std::vector<Store::Ack>& acks, auto& sent, auto publish) {
      for (const auto& a : acks) {
        auto [it, added] = sent.try_emplace({a.boat_id, a.boot_id}, a.acked_seq);
        if (!repeat && !added && it->second == a.acked_seq) continue;
        it->second = a.acked_seq;
        publish(a);
      }
      if (repeat) {
        // Runs the store no longer tracks need no receipt: forget them, so this map is bounded
        // by the store's receipts, not by every run seen since start.
        std::set<std::pair<std::string, std::uint64_t>> live_runs;
        for (const auto& a : acks) live_runs.emplace(a.boat_id, a.boot_id);
        std::erase_if(sent, [&](const auto& e) { return !live_runs.count(e.first); });
      }
    };
    send_receipts(store.acks(), receipt_sent,
                  [&](const Store::Ack& a) { dds.publish_ack(a.boat_id, a.boot_id, a.acked_seq); });
    send_receipts(store.fix_acks(), fix_receipt_sent, [&](const Store::Ack& a) {
      dds.publish_fix_ack(a.boat_id, a.boot_id, a.acked_seq);
    });
    try {
      for (const auto& topic : dds.recycle_full_readers(std::chrono::seconds(10)))
        std::fprintf(stderr,
                     "shore_server: the %s reader's table of ids was full (a publisher inventing "
                     "ids?): replaced, boats still sailing are back with their next sample\n",
                     topic.c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shore_server: cannot replace a full DDS reader: %s\n", e.what());
    }
    if (tick % 300 == 0) {  // every minute: boats and athletes silent for long leave the model
      for (const auto& id :
           fleet.forget(std::chrono::steady_clock::now(), std::chrono::seconds(o.forget_after_s)))
        hub.forget(id);
    }
  }
  http_join.finish();
  live_join.finish();
  std::printf("shore_server stopped: %llu samples committed\n",
              static_cast<unsigned long long>(store.committed()));
}

}  // namespace

int main(int argc, char** argv) {
  telltale::ShutdownSignal shutdown;  // first: every later thread inherits the blocked signals
  // A REST request builds its answer in a few transient buffers of 0.1-2 MB (a chart's tier
  // buckets and rows, an export page). With glibc's defaults each HTTP worker's arena gave those
  // pages back to the kernel after every request and faulted them in again on the next: page
  // faults were ~70 % of a chart request (perf). Fixed thresholds keep up to 16 MB of free heap
  // per arena for reuse and map only blocks over 8 MB on their own: chart requests 522 -> ~1750
  // per second (deploy/bench_chart.sh), for at most a few tens of MB of resident memory.
  mallopt(M_MMAP_THRESHOLD, 8 << 20);
  mallopt(M_TRIM_THRESHOLD, 16 << 20);
  Options o;
  int domain = -1;
  CLI::App app{"Telltale shore server: fleet over DDS -> SQLite, REST API, live stream, dashboard"};
  app.set_config("--config", "", "read options from this file (INI/TOML: key = value)");
  // --help: the dashboard's address, who may see what, the recording, the live fleet, the link.
  const std::string http = "Dashboard and HTTP";
  app.add_option("--http-port", o.http.port, "HTTP port; 0 picks a free one and prints it")
      ->capture_default_str()
      ->group(http);
  app.add_option("--bind", o.http.bind_address, "HTTP listen address (localhost by default)")
      ->capture_default_str()
      ->group(http);
  app.add_option("--web-dir", o.http.web_dir, "dashboard files")->capture_default_str()->group(http);
  app.add_option_function<std::size_t>(
         "--max-import-mb", [&o](std::size_t mb) { o.http.max_import_bytes = mb << 20; },
         "largest log file POST /api/v1/imports takes, MB (default 256)")
      ->check(CLI::Range(1, 65536))
      ->group(http);
  app.add_option("--rest-threads", o.http.rest_threads, "HTTP workers besides the streams")
      ->capture_default_str()
      ->group(http);
  app.add_option("--keep-alive-s", o.http.keep_alive_s,
                 "an idle HTTP keep-alive connection is closed after this (sooner under load)")
      ->capture_default_str()
      ->check(CLI::Range(1, 300))
      ->group(http);

  const char* security = telltale::dds::kSecurityCliGroup;  // with --security-dir
  app.add_option("--coach-token", o.coach_token,
                 "coach token (default: $TELLTALE_COACH_TOKEN, else a generated one, printed)")
      ->group(security);
  app.add_option("--analyst-token", o.analyst_tokens,
                 "an analyst token (read and export); repeatable")
      ->group(security);
  app.add_option("--athlete-token", o.athlete_tokens,
                 "BOAT_ID:TOKEN, an athlete's token for their own boat; repeatable")
      ->group(security);

  const std::string recording = "Recording";
  app.add_option("--db", o.store.path,
                 "SQLite database file (created if missing); default: "
                 "$XDG_DATA_HOME/telltale/telltale.db, else ~/.local/share/telltale/telltale.db")
      ->group(recording);
  app.add_option("--session-gap-s", o.session_gap_s,
                 "a boat silent this long starts a new session when it returns")
      ->capture_default_str()
      ->group(recording);
  app.add_option("--retention-days", o.store.retention_days,
                 "delete samples older than this (0: keep everything)")
      ->capture_default_str()
      ->group(recording);
  app.add_option("--commit-ms", o.commit_ms, "store commit interval (the durability window)")
      ->capture_default_str()
      ->group(recording);

  const std::string live = "Live fleet";
  app.add_option("--stale-ms", o.stale_ms, "a boat silent this long is stale")
      ->capture_default_str()
      ->group(live);
  app.add_option("--forget-after-s", o.forget_after_s,
                 "a boat or athlete silent this long leaves the live fleet (its recording stays)")
      ->capture_default_str()
      ->check(CLI::Range(60, 30 * 86400))
      ->group(live);
  app.add_option("--max-streams", o.http.max_stream_clients, "live-stream clients at most")
      ->capture_default_str()
      ->group(live);
  app.add_option("--stream-interval-ms", o.stream_interval_ms,
                 "a live-stream client gets each boat's latest sample at most this often")
      ->capture_default_str()
      ->check(CLI::Range(10, 5000))
      ->group(live);

  app.add_option("--domain", domain, "DDS domain id (default: $TELLTALE_DOMAIN, else 0)")
      ->group(telltale::dds::kCliGroup);
  telltale::dds::add_dds_options(app, o.dds);
  o.http.web_dir = TELLTALE_DEFAULT_WEB_DIR;
  CLI11_PARSE(app, argc, argv);
  if (domain >= 0) o.dds.domain = domain;
  try {
    run(o, shutdown);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shore_server: %s\n", e.what());
    return 1;
  }
  return 0;
}
