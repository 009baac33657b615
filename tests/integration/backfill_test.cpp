// Losing nothing on a flaky link: a boat sails through a shore crash and through a cut
// link; afterwards the shore's recording holds every sample the boat published, with no gap
// longer than two publish periods. Real processes, real DDS, real SQLite.
#include <signal.h>
#include <sqlite3.h>
#include <unistd.h>

#include "shore_fixture.hpp"
#include "stored_seqs.hpp"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;

class BackfillTest : public ShoreFixture {
 protected:
  static constexpr const char* kNeedsRoot =
      "needs root and unshare(1) for a private mount (a fault test fails, never skips, without)";
  static bool can_mount() {
    return ::geteuid() == 0 && std::filesystem::exists("/usr/bin/unshare");
  }
  /// A boat_node whose --log-dir is a fresh tmpfs mounted with `mount_options` in a mount
  /// namespace of its own (the mount goes when the boat does).
  Process boat_on_tmpfs(const std::string& boat_id, const std::string& mount_options) {
    const std::string log = dir_ + "/log-" + boat_id;
    std::filesystem::create_directories(log);
    return Process({"/usr/bin/unshare", "-m", "--propagation", "private", "sh", "-c",
                    "mount -t tmpfs -o " + mount_options + " tmpfs '" + log + "' && exec '" +
                        bin_dir() + "/boat_node' --domain " + std::to_string(domain_) +
                        " --boat-id " + boat_id + " --log-dir '" + log + "'"});
  }

  /// Stops the boat (it drains its backlog) and returns how many samples it published.
  long stop_boat(Process& boat) {
    EXPECT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
    const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
    EXPECT_TRUE(line) << boat.output();
    std::smatch m;
    if (!line || !std::regex_search(*line, m, std::regex(R"(published=(\d+))"))) return -1;
    EXPECT_NE(line->find("shore_has_all=yes"), std::string::npos) << *line;
    return std::stol(m[1]);
  }

  /// Every seq 1..published stored once, and the largest time step between stored samples.
  void expect_complete(const std::string& boat_id, long published) {
    std::this_thread::sleep_for(600ms);  // the shore's commit interval
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(db_path().c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db, "SELECT seq, t_utc_ns FROM attitude WHERE boat_id = ? ORDER BY t_utc_ns",
                       -1, &st, nullptr);
    sqlite3_bind_text(st, 1, boat_id.c_str(), -1, SQLITE_TRANSIENT);
    long count = 0;
    long expected_seq = 1;
    bool in_order = true;
    sqlite3_int64 prev_t = 0;
    sqlite3_int64 max_step = 0;
    while (sqlite3_step(st) == SQLITE_ROW) {
      const long seq = sqlite3_column_int64(st, 0);
      const sqlite3_int64 t = sqlite3_column_int64(st, 1);
      if (seq != expected_seq) in_order = false;
      if (count > 0) max_step = std::max(max_step, t - prev_t);
      prev_t = t;
      ++expected_seq;
      ++count;
    }
    sqlite3_finalize(st);
    sqlite3_close(db);
    EXPECT_EQ(count, published) << "stored vs published";
    EXPECT_TRUE(in_order) << "seqs 1..N each once, in time order";
    // 25 Hz: a publish period is 40 ms; no gap longer than two periods.
    EXPECT_LE(max_step, 80'000'000 + 1'000'000) << "largest gap " << max_step / 1000000 << " ms";
  }
};

// Given a boat sailing, when the shore is killed (SIGKILL) for 16 s and restarted on the same
// database, then after the boat stops the session holds every sample it published.
TEST_F(BackfillTest, ShoreKilledAndRestartedLosesNothing) {
  Process& boat = start_boat("bf1", {"--log-dir", dir_ + "/boatlog"});
  std::this_thread::sleep_for(4s);
  ASSERT_EQ(shore_->stop(SIGKILL), 128 + SIGKILL);
  std::this_thread::sleep_for(16s);
  start_shore();
  // The boat backfills the outage while it keeps sailing.
  ASSERT_TRUE(eventually([&] { return !boats_by_id().empty(); }, 15s));
  std::this_thread::sleep_for(6s);
  const long published = stop_boat(boat);
  ASSERT_GT(published, 25 * 20);
  expect_complete("bf1", published);
}

// Given a log directory that exists but is read-only (a mount gone read-only), the boat refuses
// to start: no "ready" line, exit status 1 (it would otherwise sail with no log at all).
TEST_F(BackfillTest, ReadOnlyLogDirectoryRefusesToStart) {
  ASSERT_TRUE(can_mount()) << kNeedsRoot;
  Process boat = boat_on_tmpfs("ro1", "ro,size=64k");
  EXPECT_FALSE(boat.wait_for_line("boat_node ready: ", 5s)) << boat.output();
  EXPECT_EQ(boat.stop(SIGINT, 5s), 1) << boat.output();
}

// Given a boat whose log disk is full (an 8 KB tmpfs), the node's status says so first, where the
// dashboard and the boats API show it (it said "ok" while the log lost every record).
TEST_F(BackfillTest, FullLogDiskIsReportedInTheNodeStatus) {
  ASSERT_TRUE(can_mount()) << kNeedsRoot;
  Process boat = boat_on_tmpfs("fl1", "size=8k");
  ASSERT_TRUE(boat.wait_for_line("boat_node ready: ", 20s)) << boat.output();
  std::string text;
  EXPECT_TRUE(eventually(
      [&] {
        const auto boats = boats_by_id();
        if (!boats.count("fl1") || !boats.at("fl1").contains("status")) return false;
        text = boats.at("fl1")["status"]["health_text"].get<std::string>();
        return text.rfind("SESSION LOG FAILING (No space left on device)", 0) == 0;
      },
      20s))
      << text;
  // The card's first badge says so (the dashboard shows `problems`).
  const auto problems = boats_by_id().at("fl1")["problems"];
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems[0]["code"], "log_failing") << problems;
  boat.stop(SIGINT, 15s);
}

// Given a boat sailing, when its shore is replaced by one on an empty database (a fresh or
// replaced disk), then the boat follows the new shore's lower receipt: it sends the run from its
// start, in order, once (not the whole tail every 5 s), and the new database holds all of it.
TEST_F(BackfillTest, ShoreOnAnEmptyDatabaseGetsTheRunFromItsStart) {
  Process& boat = start_boat("bf9", {"--log-dir", dir_ + "/boatlog"});
  ASSERT_TRUE(eventually([&] { return boats_by_id().count("bf9") == 1; }, 10s));
  std::this_thread::sleep_for(6s);
  ASSERT_EQ(shore_->stop(SIGINT), 0);
  for (const char* ext : {"", "-wal", "-shm"}) std::filesystem::remove(db_path() + ext);
  start_shore();
  ASSERT_TRUE(eventually([&] { return boats_by_id().count("bf9") == 1; }, 15s));
  std::this_thread::sleep_for(12s);
  const long published = stop_boat(boat);
  ASSERT_GT(published, 25 * 15);
  expect_complete("bf9", published);
  std::smatch m;
  const std::string out = boat.output();
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(resent=(\d+))"))) << out;
  EXPECT_LE(std::stol(m[1]), 2 * published) << "the tail resent again and again";
}

// Given a boat whose every outgoing packet is dropped for 15 s (Fast DDS's test transport), when
// the link returns, then the shore marked it stale meanwhile and the session is complete after.
TEST_F(BackfillTest, CutLinkIsBackfilled) {
  Process& boat = start_boat("bf2", {"--log-dir", dir_ + "/boatlog", "--fault-drop-link", "3:15"});
  ASSERT_TRUE(eventually([&] { return boats_by_id().count("bf2") == 1; }, 10s));
  // During the cut the boat goes stale on the shore.
  ASSERT_TRUE(eventually(
      [&] {
        const auto boats = boats_by_id();
        return boats.count("bf2") && boats.at("bf2")["stale"].get<bool>();
      },
      10s));
  // After it, live again.
  ASSERT_TRUE(eventually(
      [&] {
        const auto boats = boats_by_id();
        return boats.count("bf2") && !boats.at("bf2")["stale"].get<bool>();
      },
      25s));
  std::this_thread::sleep_for(5s);
  const long published = stop_boat(boat);
  ASSERT_GT(published, 25 * 20);
  expect_complete("bf2", published);
}

/// A field `name=value` of the process's output so far (the first occurrence), or "".
std::string field(const Process& p, const std::string& name) {
  std::smatch m;
  const std::string& out = p.output();
  return std::regex_search(out, m, std::regex(name + R"(=([0-9a-f]+))")) ? m[1].str() : "";
}

// Given a boat stopped while the shore was down (its drain gives up: the run is only in its log),
// when the boat starts again with the shore up, then it delivers the earlier run from the log
// beside the new one, marks it delivered, and a third start has nothing left to deliver.
TEST_F(BackfillTest, EarlierRunDeliveredAtTheNextStart) {
  ASSERT_EQ(shore_->stop(SIGTERM), 0);
  const std::vector<std::string> log = {"--log-dir", dir_ + "/boatlog"};
  long first_published = 0;
  std::uint64_t first_boot = 0;
  {
    Process& boat = start_boat("bf3", log);
    first_boot = std::stoull(field(boat, "boot"), nullptr, 16);
    std::this_thread::sleep_for(3s);
    ASSERT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
    const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
    ASSERT_TRUE(line) << boat.output();
    EXPECT_NE(line->find("shore_has_all=no"), std::string::npos) << *line;
    first_published = std::stol(field(boat, "published"));
    ASSERT_GT(first_published, 25 * 2);
  }
  boats_.clear();
  start_shore();
  Process& boat = start_boat("bf3", log);
  EXPECT_EQ(field(boat, "earlier_runs"), "1");
  const auto delivered = boat.wait_for_line("boat_node earlier run ", 30s);
  ASSERT_TRUE(delivered) << boat.output();
  EXPECT_NE(delivered->find("delivered"), std::string::npos) << *delivered;
  std::this_thread::sleep_for(600ms);  // the shore's commit interval
  EXPECT_EQ(stored_seqs(db_path(), "bf3", first_published, first_boot), first_published);
  const long second_published = stop_boat(boat);
  EXPECT_EQ(field(boat, "earlier_runs_pending"), "0");
  std::this_thread::sleep_for(600ms);
  const std::uint64_t second_boot = std::stoull(field(boat, "boot"), nullptr, 16);
  EXPECT_EQ(stored_seqs(db_path(), "bf3", second_published, second_boot), second_published);
  boats_.clear();
  Process& third = start_boat("bf3", log);
  EXPECT_EQ(field(third, "earlier_runs"), "0") << third.output();
}

// --- GNSS fixes: logged and backfilled like the attitude -----------------------------------------

/// How often the database holds each fix seq of the boat's run `boot_id` (seq -> rows).
std::map<long, long> stored_fix_seqs(const std::string& db_path, const std::string& boat,
                                     std::uint64_t boot_id) {
  std::map<long, long> out;
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db,
                           "SELECT seq, COUNT(*) FROM fixes WHERE boat_id = ?1 AND boot_id = ?2 "
                           "GROUP BY seq",
                           -1, &st, nullptr) == SQLITE_OK) {
      sqlite3_bind_text(st, 1, boat.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_int64(st, 2, static_cast<sqlite3_int64>(boot_id));
      while (sqlite3_step(st) == SQLITE_ROW)
        out[static_cast<long>(sqlite3_column_int64(st, 0))] =
            static_cast<long>(sqlite3_column_int64(st, 1));
    }
    sqlite3_finalize(st);
  }
  sqlite3_close(db);
  return out;
}

/// Every fix seq 1..published of the run stored exactly once; the seqs missing or doubled, as
/// ranges, in the failure message.
void expect_fixes_complete(const std::string& db_path, const std::string& boat,
                           std::uint64_t boot_id, long published) {
  const auto seqs = stored_fix_seqs(db_path, boat, boot_id);
  std::string missing, doubled;
  for (long seq = 1; seq <= published; ++seq) {
    const auto it = seqs.find(seq);
    if (it == seqs.end())
      missing += " " + std::to_string(seq);
    else if (it->second != 1)
      doubled += " " + std::to_string(seq);
  }
  if (missing.size() > 200) missing = missing.substr(0, 200) + " ...";
  EXPECT_TRUE(missing.empty()) << "fixes not stored:" << missing;
  EXPECT_TRUE(doubled.empty()) << "fixes stored twice:" << doubled;
  EXPECT_EQ(static_cast<long>(seqs.size()), published) << "distinct fix seqs stored vs published";
}

// Given a boat sailing the simulated course (a fix every 0.1 s), when the shore is killed for 15 s
// and restarted on the same database, then after the boat stops every fix it published is stored
// once: the live ones, and the outage's from the boat's log on the fix backfill topic.
TEST_F(BackfillTest, FixesOfAShoreOutageAreBackfilled) {
  Process& boat = start_boat("fx1", {"--log-dir", dir_ + "/boatlog"});
  const std::uint64_t boot = std::stoull(field(boat, "boot"), nullptr, 16);
  std::this_thread::sleep_for(4s);
  ASSERT_EQ(shore_->stop(SIGKILL), 128 + SIGKILL);
  std::this_thread::sleep_for(15s);
  start_shore();
  ASSERT_TRUE(eventually([&] { return !boats_by_id().empty(); }, 15s));
  std::this_thread::sleep_for(6s);
  ASSERT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
  const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
  ASSERT_TRUE(line) << boat.output();
  EXPECT_NE(line->find("shore_has_all_fixes=yes"), std::string::npos) << *line;
  const long fixes = std::stol(field(boat, "fixes"));
  ASSERT_GT(fixes, 10 * 20) << *line;
  std::this_thread::sleep_for(600ms);  // the shore's commit interval
  expect_fixes_complete(db_path(), "fx1", boot, fixes);
  // The track the REST API serves has the outage's positions too: no hole of the outage's length
  // (the simulated course has a position every 0.1 s).
  const auto track = get_json("/api/v1/boats/fx1/track?max_points=100000");
  ASSERT_TRUE(track.is_object() && track["t_s"].is_array()) << track;
  ASSERT_GT(track["t_s"].size(), 10u * 20);
  double largest_step_s = 0;
  for (std::size_t i = 1; i < track["t_s"].size(); ++i)
    largest_step_s =
        std::max(largest_step_s, track["t_s"][i].get<double>() - track["t_s"][i - 1].get<double>());
  EXPECT_LT(largest_step_s, 1.0) << "a hole in the track";
}

// Given a boat whose every outgoing packet is dropped for 15 s, when the link returns, then every
// fix of the cut is stored once (the fix receipts told the boat what was missing).
TEST_F(BackfillTest, FixesOfACutLinkAreBackfilled) {
  Process& boat = start_boat("fx2", {"--log-dir", dir_ + "/boatlog", "--fault-drop-link", "3:15"});
  const std::uint64_t boot = std::stoull(field(boat, "boot"), nullptr, 16);
  ASSERT_TRUE(eventually([&] { return boats_by_id().count("fx2") == 1; }, 10s));
  std::this_thread::sleep_for(22s);  // through the cut and back
  ASSERT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
  const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
  ASSERT_TRUE(line) << boat.output();
  EXPECT_NE(line->find("shore_has_all_fixes=yes"), std::string::npos) << *line;
  const long fixes = std::stol(field(boat, "fixes"));
  ASSERT_GT(fixes, 10 * 20) << *line;
  std::this_thread::sleep_for(600ms);
  expect_fixes_complete(db_path(), "fx2", boot, fixes);
}

// Given a boat stopped while the shore was down, when it starts again with the shore up, then it
// delivers the earlier run's fixes from its log (and marks them delivered), beside its new run.
TEST_F(BackfillTest, EarlierRunFixesDeliveredAtTheNextStart) {
  ASSERT_EQ(shore_->stop(SIGTERM), 0);
  const std::vector<std::string> log = {"--log-dir", dir_ + "/boatlog"};
  long first_fixes = 0;
  std::uint64_t first_boot = 0;
  {
    Process& boat = start_boat("fx3", log);
    first_boot = std::stoull(field(boat, "boot"), nullptr, 16);
    std::this_thread::sleep_for(3s);
    ASSERT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
    const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
    ASSERT_TRUE(line) << boat.output();
    EXPECT_NE(line->find("shore_has_all_fixes=no"), std::string::npos) << *line;
    first_fixes = std::stol(field(boat, "fixes"));
    ASSERT_GT(first_fixes, 10);
  }
  boats_.clear();
  start_shore();
  Process& boat = start_boat("fx3", log);
  EXPECT_EQ(field(boat, "earlier_fix_runs"), "1") << boat.output();
  const auto delivered = boat.wait_for_line("boat_node fixes: earlier run ", 30s);
  ASSERT_TRUE(delivered) << boat.output();
  EXPECT_NE(delivered->find("delivered"), std::string::npos) << *delivered;
  std::this_thread::sleep_for(600ms);  // the shore's commit interval
  expect_fixes_complete(db_path(), "fx3", first_boot, first_fixes);
  ASSERT_EQ(boat.stop(SIGINT, 15s), 0) << boat.output();
  const auto line = boat.wait_for_line("boat_node stopped: ", 1s);
  ASSERT_TRUE(line) << boat.output();
  EXPECT_NE(line->find("earlier_fix_runs_pending=0"), std::string::npos) << *line;
  boats_.clear();
  Process& third = start_boat("fx3", log);
  EXPECT_EQ(field(third, "earlier_fix_runs"), "0") << third.output();
}

}  // namespace
}  // namespace telltale::testing
