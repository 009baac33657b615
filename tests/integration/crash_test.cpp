// Crash safety: a shore ingesting three boats is SIGKILLed at random moments
// (seeded, printed; TELLTALE_CRASH_SEED repeats a run) 20 times and restarted on the same
// database each time. After every kill: the database the restart opens passes
// PRAGMA integrity_check, the alarm acknowledgements answered before the kill are still there,
// and the newest stored sample is about the durability window (--commit-ms, plus one publish
// period and delivery) older than the kill: in the median over the kills, and with a second's
// slack for scheduling in any one. At the end the boats' backfill has refilled every
// gap: each boat's samples 1..N are all stored; /dev/shm holds no more entries than before.
#include <signal.h>
#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "shore_fixture.hpp"
#include "stored_seqs.hpp"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;

constexpr int kCommitMs = 250;
constexpr int kCycles = 20;
constexpr int kBoats = 3;

std::uint64_t utc_now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

std::size_t shm_entries() {
  std::size_t n = 0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/dev/shm", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec))
    ++n;
  return n;
}

class CrashTest : public ShoreFixture {
 protected:
  std::vector<std::string> shore_flags() const override {
    return {"--commit-ms", std::to_string(kCommitMs)};
  }

  static std::string id(int i) { return "cr" + std::to_string(i); }

  bool all_boats_fresh(std::uint64_t since_utc_ns) const {
    const auto b = boats_by_id();
    for (int i = 0; i < kBoats; ++i) {
      const auto it = b.find(id(i));
      if (it == b.end() || it->second["stale"].get<bool>() ||
          it->second["t_utc_ns"].get<std::uint64_t>() <= since_utc_ns)
        return false;
    }
    return true;
  }

  /// A fresh rule that every boat breaks at once (heel outside 89..90 deg), so each cycle raises
  /// new events to acknowledge. Returns the acknowledged event ids.
  std::vector<std::uint64_t> raise_and_ack(int cycle) {
    auto c = client();
    const nlohmann::json rules = nlohmann::json::array({{{"id", "crash-" + std::to_string(cycle)},
                                                         {"quantity", "heel"},
                                                         {"min_deg", 89.0},
                                                         {"max_deg", 90.0},
                                                         {"level", "alarm"}}});
    auto put = c.Put("/api/v1/alarms/rules", bearer(), rules.dump(), "application/json");
    EXPECT_TRUE(put && put->status == 200) << (put ? put->body : "no answer");
    std::vector<std::uint64_t> ids;
    const std::string rule = "crash-" + std::to_string(cycle);
    EXPECT_TRUE(eventually(
        [&] {
          ids.clear();
          const auto events = get_json("/api/v1/alarms/events?active=true");
          if (!events.is_array()) return false;
          for (const auto& e : events)
            if (e["rule_id"] == rule) ids.push_back(e["id"].get<std::uint64_t>());
          return ids.size() == kBoats;
        },
        10s))
        << "events raised for " << rule;
    for (const auto event : ids) {
      auto res = c.Post("/api/v1/alarms/events/" + std::to_string(event) + "/ack", bearer(), "",
                        "application/json");
      EXPECT_TRUE(res && res->status == 200) << (res ? res->body : "no answer");
    }
    return ids;
  }

  /// On a copy of the files the killed shore left (what its restart will open): the integrity
  /// check's answer, and per boat how old the newest sample before the kill is, in ms.
  std::string check_copy(std::uint64_t kill_utc_ns, std::vector<double>& loss_ms) {
    const std::string snap = dir_ + "/snapshot.db";
    std::filesystem::remove(snap);
    std::filesystem::remove(snap + "-wal");
    std::filesystem::copy_file(db_path(), snap);
    if (std::filesystem::exists(db_path() + "-wal"))
      std::filesystem::copy_file(db_path() + "-wal", snap + "-wal");
    sqlite3* db = nullptr;
    std::string integrity = "cannot open";
    if (sqlite3_open_v2(snap.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) == SQLITE_OK) {
      sqlite3_stmt* st = nullptr;
      sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &st, nullptr);
      integrity.clear();
      while (sqlite3_step(st) == SQLITE_ROW)
        integrity += reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
      sqlite3_finalize(st);
      sqlite3_prepare_v2(db,
                         "SELECT MAX(t_utc_ns) FROM attitude WHERE boat_id = ? AND t_utc_ns < ?",
                         -1, &st, nullptr);
      for (int i = 0; i < kBoats; ++i) {
        sqlite3_reset(st);
        sqlite3_bind_text(st, 1, id(i).c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(st, 2, static_cast<sqlite3_int64>(kill_utc_ns));
        double ms = 1e9;
        if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_type(st, 0) != SQLITE_NULL)
          ms = static_cast<double>(kill_utc_ns -
                                   static_cast<std::uint64_t>(sqlite3_column_int64(st, 0))) *
               1e-6;
        loss_ms.push_back(ms);
      }
      sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return integrity;
  }

  long count_seqs(const std::string& boat, long max_seq) const {
    return stored_seqs(db_path(), boat, max_seq);
  }
};

TEST_F(CrashTest, TwentyKillsDuringIngest) {
  const std::size_t shm_before = shm_entries();
  unsigned seed = static_cast<unsigned>(std::random_device{}());
  if (const char* env = std::getenv("TELLTALE_CRASH_SEED"))
    seed = static_cast<unsigned>(std::stoul(env));
  std::printf("[crash] seed=%u (TELLTALE_CRASH_SEED=%u repeats it)\n", seed, seed);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> run_ms(100, 2500);

  for (int i = 0; i < kBoats; ++i) start_boat(id(i), {"--log-dir", dir_ + "/log_" + id(i)});
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::uint64_t> acked;
  double worst_loss_ms = 0;
  std::vector<double> cycle_losses;
  for (int cycle = 1; cycle <= kCycles; ++cycle) {
    // Ingest is running: every boat live on this shore instance, and fresh events acknowledged.
    const std::uint64_t up_utc = utc_now_ns();
    ASSERT_TRUE(eventually([&] { return all_boats_fresh(up_utc); }, 30s)) << "cycle " << cycle;
    for (const auto e : raise_and_ack(cycle)) acked.push_back(e);
    const int wait_ms = run_ms(rng);
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
    const std::uint64_t kill_utc = utc_now_ns();
    ASSERT_EQ(shore_->stop(SIGKILL), 128 + SIGKILL);
    std::vector<double> loss_ms;
    const std::string integrity = check_copy(kill_utc, loss_ms);
    EXPECT_EQ(integrity, "ok") << "cycle " << cycle;
    double cycle_loss = 0;
    for (const double ms : loss_ms) cycle_loss = std::max(cycle_loss, ms);
    worst_loss_ms = std::max(worst_loss_ms, cycle_loss);
    cycle_losses.push_back(cycle_loss);
    // A writer that stalls: the newest stored sample is older than the durability window
    // (--commit-ms, one publish period of 40 ms) by more than a second of scheduling, which a
    // loaded machine under the sanitizers can cost any process (CI once saw 533 ms against 290).
    EXPECT_LE(cycle_loss, kCommitMs + 40 + 1000)
        << "cycle " << cycle << ": newest stored sample " << cycle_loss << " ms before the kill";
    std::printf(
        "[crash] cycle %2d: killed after %4d ms, integrity %s, newest stored %.0f ms "
        "before the kill\n",
        cycle, wait_ms, integrity.c_str(), cycle_loss);
    ASSERT_NO_FATAL_FAILURE(start_shore());
    // Every acknowledgement answered before any kill so far is still there.
    const auto events = get_json("/api/v1/alarms/events?limit=10000");
    ASSERT_TRUE(events.is_array());
    std::set<std::uint64_t> still_acked;
    for (const auto& e : events)
      if (!e["acknowledged_at"].is_null()) still_acked.insert(e["id"].get<std::uint64_t>());
    for (const auto e : acked) EXPECT_TRUE(still_acked.count(e)) << "ack of event " << e << " lost";
  }
  // A writer slower than its interval: killed at a uniformly random moment of the commit cycle,
  // the newest stored sample is typically half an interval, a half publish period, the delivery
  // and the commit old (median 184 ms measured at 250 ms; commits twice as far apart: 372).
  std::vector<double> sorted = cycle_losses;
  std::sort(sorted.begin(), sorted.end());
  const double median_loss_ms = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  EXPECT_LE(median_loss_ms, kCommitMs + 40) << "the store commits less often than --commit-ms";
  // Backfill refills what the kills lost: every boat live on the last shore instance and every
  // sample but the newest 60 (left to the live path) stored. Then every boat stops (draining)
  // and is compared.
  const std::uint64_t last_up_utc = utc_now_ns();
  EXPECT_TRUE(eventually([&] { return all_boats_fresh(last_up_utc); }, 30s));
  for (int i = 0; i < kBoats; ++i) {
    EXPECT_TRUE(eventually(
        [&] {
          const auto b = boats_by_id();
          if (!b.count(id(i))) return false;
          const long settled = b.at(id(i))["seq"].get<long>() - 60;
          return count_seqs(id(i), settled) >= settled;
        },
        60s))
        << id(i) << " not refilled; missing "
        << missing_seqs(db_path(), id(i), boats_by_id()[id(i)]["seq"].get<long>());
  }
  for (int i = 0; i < kBoats; ++i) {
    Process& boat = *boats_[static_cast<std::size_t>(i)];
    EXPECT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
    const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
    ASSERT_TRUE(line) << boat.output();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(*line, m, std::regex(R"(published=(\d+))")));
    const long published = std::stol(m[1]);
    EXPECT_NE(line->find("shore_has_all=yes"), std::string::npos) << *line;
    std::this_thread::sleep_for(2 * std::chrono::milliseconds(kCommitMs));
    const long stored = count_seqs(id(i), published);
    EXPECT_EQ(stored, published) << id(i) << " missing "
                                 << missing_seqs(db_path(), id(i), published);
    std::printf("[crash] %s published=%ld stored=%ld\n", id(i).c_str(), published, stored);
  }
  shore_->stop(SIGTERM);
  const std::size_t shm_after = shm_entries();
  EXPECT_LE(shm_after, shm_before) << "/dev/shm grew across the crashes";
  std::printf(
      "[crash] %d kills in %.0f s, acks kept %zu/%zu, loss at a kill median %.0f ms, worst %.0f "
      "ms (window %d ms), /dev/shm entries %zu -> %zu\n",
      kCycles, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
      acked.size(), acked.size(), median_loss_ms, worst_loss_ms, kCommitMs, shm_before, shm_after);
  std::fflush(stdout);
}

}  // namespace
}  // namespace telltale::testing
