// The shore's SQLite store on real files: migration from an older schema, duplicate-free merging
// of re-sent samples, sessions split on gaps, and the receipts that drive the boats' backfill.
#include "store.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sqlite3.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <future>
#include <map>
#include <thread>

#include "small_tmpfs.hpp"
#include "temp_dir_test.hpp"
#include "tier_check.hpp"

namespace telltale::shore {
namespace {

constexpr std::uint64_t kSecond = 1000000000ULL;
constexpr std::uint64_t kT0 = 1795300000ULL * kSecond;

class StoreTest : public test::TempDirTest {
 protected:
  StoreTest() : TempDirTest("telltale_store_") {}
  StoreConfig config() const {
    StoreConfig c;
    c.path = (dir_ / "s.db").string();
    c.commit_interval = std::chrono::milliseconds(20);
    c.session_gap = std::chrono::seconds(60);
    return c;
  }
  static AttitudeSample sample(const std::string& boat, std::uint64_t boot, std::uint64_t seq,
                               std::uint64_t t_ns) {
    AttitudeSample s;
    s.boat_id = boat;
    s.boot_id = boot;
    s.seq = seq;
    s.t_utc_ns = t_ns;
    s.heel_deg = 10.0;
    s.pitch_deg = 1.0;
    s.heading_deg = std::nan("");
    return s;
  }
};

// Given a database written before boot_id existed, when a new shore opens it, then the old
// samples are kept and new ones (with boot ids) are stored beside them.
TEST_F(StoreTest, MigratesAnOlderSchemaKeepingItsData) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(config().path.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(
        sqlite3_exec(db,
                     "CREATE TABLE attitude (boat_id TEXT NOT NULL, t_utc_ns INTEGER NOT NULL,"
                     " seq INTEGER NOT NULL, heel_deg REAL NOT NULL, pitch_deg REAL NOT NULL,"
                     " heading_deg REAL, heel_rate_deg_s REAL, pitch_rate_deg_s REAL,"
                     " yaw_rate_deg_s REAL, accel_weight REAL, quality REAL,"
                     " PRIMARY KEY (boat_id, t_utc_ns)) WITHOUT ROWID;"
                     "INSERT INTO attitude VALUES ('old', 1, 1, 5, 0, NULL, 0, 0, 0, 0, 1);",
                     nullptr, nullptr, nullptr),
        SQLITE_OK);
    sqlite3_close(db);
  }
  Store store(config());
  store.enqueue(sample("new", 42, 1, kT0));
  store.flush();
  EXPECT_EQ(store.count("old"), 1);
  EXPECT_EQ(store.count("new"), 1);
}

TEST_F(StoreTest, RefusesADatabaseFromANewerBuild) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(config().path.c_str(), &db), SQLITE_OK);
    sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  EXPECT_THROW(Store store(config()), StoreError);
}

// Re-sent samples merge without duplicates; a gap longer than session_gap starts a new session;
// the receipt is the highest seq with every earlier one stored, and moves once a hole is filled.
TEST_F(StoreTest, DeduplicatesSplitsSessionsAndAcknowledgesContiguousRuns) {
  Store store(config());
  for (std::uint64_t i = 1; i <= 10; ++i)
    if (i != 4) store.enqueue(sample("b", 7, i, kT0 + i * kSecond / 25));
  store.flush();
  auto acks = store.acks();
  ASSERT_EQ(acks.size(), 1u);
  EXPECT_EQ(acks[0].boot_id, 7u);
  EXPECT_EQ(acks[0].acked_seq, 3u);  // seq 4 is missing
  // Backfill: seq 4 arrives, and 5..6 again.
  for (std::uint64_t i : {4ULL, 5ULL, 6ULL})
    store.enqueue(sample("b", 7, i, kT0 + i * kSecond / 25));
  store.flush();
  EXPECT_EQ(store.count("b"), 10);
  EXPECT_EQ(store.acks()[0].acked_seq, 10u);
  // Two minutes later: a new session.
  store.enqueue(sample("b", 7, 11, kT0 + 120 * kSecond));
  store.flush();
  const auto sessions = store.sessions(std::string("b"), 0, UINT64_MAX);
  ASSERT_EQ(sessions.size(), 2u);
  std::int64_t total = 0;
  for (const auto& s : sessions) total += s.samples;
  EXPECT_EQ(total, 11);
  // A new run of the boat has a receipt of its own; the earlier run's stays (its log may still
  // be delivering).
  store.enqueue(sample("b", 8, 1, kT0 + 121 * kSecond));
  store.flush();
  acks = store.acks();
  ASSERT_EQ(acks.size(), 2u);
  EXPECT_EQ(acks[0].boot_id, 7u);
  EXPECT_EQ(acks[0].acked_seq, 11u);
  EXPECT_EQ(acks[1].boot_id, 8u);
  EXPECT_EQ(acks[1].acked_seq, 1u);
}

// Given a boat sailing north at 3 m/s with 1 m of position noise per fix at 10 Hz, the
// distance sailed is the speed integrated (not the noisy position steps, which add ~1 m per
// fix), a 30 s receiver gap adds nothing, the track thins evenly in time, and a no-fix epoch is
// stored but never part of the track.
TEST_F(StoreTest, FixesGiveDistanceSpeedsAndATrack) {
  Store store(config());
  std::uint64_t seq = 0;
  const auto fix = [&](double t_s, double north_m, const char* kind = "3d") {
    FixSample f;
    f.boat_id = "b";
    f.seq = ++seq;
    f.t_utc_ns = kT0 + static_cast<std::uint64_t>(t_s * 1e9);
    f.fix = kind;
    const bool has = std::string(kind) != "none";
    f.lat_deg = has ? 54.0 + north_m / 111195.0 : std::nan("");
    f.lon_deg = has ? 10.0 : std::nan("");
    f.sog_m_s = has ? 3.0 : std::nan("");
    f.cog_deg = has ? 0.0 : std::nan("");
    f.satellites = 9;
    f.hdop = 0.9;
    return f;
  };
  double noise = 1.0;
  for (int i = 0; i <= 600; ++i) {  // 60 s
    noise = -noise;
    store.enqueue(fix(i * 0.1, 3.0 * i * 0.1 + noise));
  }
  store.enqueue(fix(75.0, 225.0, "none"));  // 30 s of silence, then no fix, then fixes again
  for (int i = 0; i <= 100; ++i) store.enqueue(fix(90.0 + i * 0.1, 270.0 + 0.3 * i));
  store.enqueue(sample("b", 1, 1, kT0));
  store.flush();
  const FixStats st = store.fix_stats("b", 0, UINT64_MAX);
  EXPECT_EQ(st.fixes, 601 + 101);
  EXPECT_NEAR(st.distance_m, 3.0 * (60.0 + 10.0), 0.01);  // the gap adds nothing
  EXPECT_NEAR(st.time_with_fix_s, 70.0, 1e-6);
  EXPECT_NEAR(st.sog_mean_m_s, 3.0, 1e-9);
  EXPECT_NEAR(st.sog_max_m_s, 3.0, 1e-9);
  const auto all = store.track("b", 0, UINT64_MAX, 100000);
  EXPECT_EQ(all.size(), 702u);
  for (const auto& f : all) EXPECT_NE(f.fix, "none");
  const auto thin = store.track("b", 0, UINT64_MAX, 50);
  ASSERT_LE(thin.size(), 50u);
  EXPECT_GE(thin.size(), 30u);  // the times that fall in the 30 s gap have no point of their own
  EXPECT_EQ(thin.front().t_utc_ns, all.front().t_utc_ns);
  EXPECT_EQ(thin.back().t_utc_ns, all.back().t_utc_ns);
  // Evenly in time: no two kept points closer than half the mean spacing (except across the gap).
  const double spacing = 100.0 / 49.0;
  for (std::size_t i = 1; i < thin.size(); ++i)
    EXPECT_GT(static_cast<double>(thin[i].t_utc_ns - thin[i - 1].t_utc_ns) * 1e-9, 0.4 * spacing);
  // A range: only its fixes.
  EXPECT_EQ(store.track("b", kT0 + 90 * kSecond, UINT64_MAX, 100000).size(), 101u);
}

// After a restart the receipt of a run is rebuilt from what is on disk.
TEST_F(StoreTest, ReceiptsSurviveARestart) {
  {
    Store store(config());
    for (std::uint64_t i = 1; i <= 5; ++i) store.enqueue(sample("b", 9, i, kT0 + i * kSecond));
    store.flush();
  }
  Store store(config());
  store.enqueue(sample("b", 9, 7, kT0 + 7 * kSecond));
  store.flush();
  EXPECT_EQ(store.acks()[0].acked_seq, 5u);  // 6 still missing
  store.enqueue(sample("b", 9, 6, kT0 + 6 * kSecond));
  store.flush();
  EXPECT_EQ(store.acks()[0].acked_seq, 7u);
}

// Fix receipts: per run, the highest fix seq with every fix up to it stored; a fix that comes
// twice (live, then backfilled from the boat's log) is one row; after a restart the receipt is
// rebuilt from the fixes on disk; the attitude's receipts are not the fixes'.
TEST_F(StoreTest, FixReceiptsCountStoredFixesOnceAndSurviveARestart) {
  const auto fix = [](std::uint64_t boot, std::uint64_t seq) {
    FixSample f;
    f.boat_id = "b";
    f.boot_id = boot;
    f.seq = seq;
    f.t_utc_ns = kT0 + seq * kSecond / 10;
    f.fix = "3d";
    f.lat_deg = 54.0;
    f.lon_deg = 10.0;
    f.sog_m_s = 3.0;
    f.cog_deg = 90.0;
    f.satellites = 9;
    f.hdop = 0.9;
    return f;
  };
  const auto fix_rows = [&] {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(config().path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr),
              SQLITE_OK);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM fixes WHERE boat_id = 'b'", -1, &st, nullptr);
    sqlite3_step(st);
    const auto n = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    return n;
  };
  {
    Store store(config());
    for (std::uint64_t seq : {1u, 2u, 3u, 5u, 6u}) store.enqueue(fix(0x31, seq));
    store.enqueue(sample("b", 0x31, 1, kT0));
    store.flush();
    ASSERT_EQ(store.fix_acks().size(), 1u);
    EXPECT_EQ(store.fix_acks()[0].boot_id, 0x31u);
    EXPECT_EQ(store.fix_acks()[0].acked_seq, 3u);  // 4 missing
    EXPECT_EQ(store.acks()[0].acked_seq, 1u);      // the attitude's own
    for (std::uint64_t seq : {2u, 3u, 4u})
      store.enqueue(fix(0x31, seq));  // backfill, 2 and 3 again
    store.flush();
    EXPECT_EQ(store.fix_acks()[0].acked_seq, 6u);
    EXPECT_EQ(fix_rows(), 6);
  }
  Store store(config());
  store.enqueue(fix(0x31, 8));
  store.flush();
  EXPECT_EQ(store.fix_acks()[0].acked_seq, 6u);  // 1..6 from disk, 7 missing
  store.enqueue(fix(0x31, 7));
  store.flush();
  EXPECT_EQ(store.fix_acks()[0].acked_seq, 8u);
  EXPECT_EQ(fix_rows(), 8);
}

// A link cut longer than the session gap: live data after the cut opens a second session; when
// the backfill of the cut closes the gap, the two become one session holding every sample.
TEST_F(StoreTest, BackfillThatClosesTheGapMergesTheSessions) {
  Store store(config());
  for (std::uint64_t i = 0; i <= 10; ++i) store.enqueue(sample("b", 7, i + 1, kT0 + i * kSecond));
  store.flush();
  // Cut from 10 s to 300 s; live again from 300 s.
  for (std::uint64_t i = 300; i <= 305; ++i)
    store.enqueue(sample("b", 7, i + 1, kT0 + i * kSecond));
  store.flush();
  ASSERT_EQ(store.sessions(std::string("b"), 0, UINT64_MAX).size(), 2u);
  // Backfill of the cut, oldest first, in a few batches.
  for (std::uint64_t from = 11; from < 300; from += 100) {
    for (std::uint64_t i = from; i < std::min<std::uint64_t>(from + 100, 300); ++i)
      store.enqueue(sample("b", 7, i + 1, kT0 + i * kSecond));
    store.flush();
  }
  // Live data keeps extending the merged session.
  store.enqueue(sample("b", 7, 307, kT0 + 306 * kSecond));
  store.flush();
  const auto sessions = store.sessions(std::string("b"), 0, UINT64_MAX);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].start_ns, kT0);
  EXPECT_EQ(sessions[0].end_ns, kT0 + 306 * kSecond);
  EXPECT_EQ(sessions[0].samples, 307);
  EXPECT_EQ(store.count("b"), 307);
}

// Given a shore keeping 7 days and a boat whose clock is 10 days behind (no RTC, no fix yet),
// when the retention pass runs, then the samples that arrived today stay: age is the shore's
// arrival time, not the boat's clock.
TEST_F(StoreTest, RetentionGoesByArrivalNotByTheBoatsClock) {
  const auto now_ns =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  const std::uint64_t behind = now_ns - 10 * 86400 * kSecond;
  {
    Store store(config());
    for (std::uint64_t i = 1; i <= 50; ++i)
      store.enqueue(sample("late", 3, i, behind + i * kSecond));
    store.flush();
  }
  auto c = config();
  c.retention_days = 7;
  {
    Store store(c);  // the first retention pass runs at start
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(store.count("late"), 50);
    EXPECT_EQ(store.sessions(std::string("late"), 0, UINT64_MAX).size(), 1u);
  }
  // The same session once it arrived more than 7 days ago (set in the file): it goes, samples
  // and all.
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(c.path.c_str(), &db), SQLITE_OK);
    const std::string sql =
        "UPDATE sessions SET received_ns = " + std::to_string(now_ns - 8 * 86400 * kSecond);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
  }
  Store store(c);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(store.count("late"), 0);
  EXPECT_TRUE(store.sessions(std::string("late"), 0, UINT64_MAX).empty());
}

// Given 10 minutes of 25 Hz samples stored out of order (the second half live, the first half
// backfilled after it, some twice), then every chart tier holds exactly the count and the extremes
// a brute-force pass over the samples finds; and a database from before the tiers gets them built
// when it is opened.
TEST_F(StoreTest, ChartTiersHoldTheCountAndExtremesOfEveryBucket) {
  std::vector<AttitudeSample> samples;
  for (std::uint64_t i = 0; i < 15000; ++i) {
    auto s = sample("tier", 5, i + 1, kT0 + i * kSecond / 25);
    s.heel_deg = 20.0 * std::sin(static_cast<double>(i) * 0.013) + static_cast<double>(i % 7);
    s.pitch_deg = 5.0 * std::cos(static_cast<double>(i) * 0.029) - static_cast<double>(i % 5);
    samples.push_back(s);
  }
  {
    Store store(config());
    for (std::size_t i = samples.size() / 2; i < samples.size(); ++i) store.enqueue(samples[i]);
    store.flush();
    for (std::size_t i = 0; i < samples.size() / 2; ++i) store.enqueue(samples[i]);
    for (std::size_t i = 0; i < 500; ++i) store.enqueue(samples[i]);  // re-sent: ignored
    store.flush();
    ASSERT_EQ(store.count("tier"), static_cast<std::int64_t>(samples.size()));
    expect_tiers_hold(store, "tier");
  }
  {  // The same database as an older shore left it: no tiers.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(config().path.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db,
                           "DROP TABLE attitude_tier; "
                           "PRAGMA user_version = 2;",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  Store reopened(config());
  expect_tiers_hold(reopened, "tier");
}

// Given a slow reader holding a read connection (an export streaming a long session), then other
// queries still answer at once: the store reads through a pool of connections, not one behind a
// mutex (where every chart request queued behind the export).
TEST_F(StoreTest, ASlowReadDoesNotHoldUpOtherQueries) {
  Store store(config());
  store.enqueue(sample("q", 1, 1, kT0));
  store.flush();
  std::promise<void> holding;
  std::promise<void> release;
  std::thread slow([&] {
    store.read([&](sqlite3*) {
      holding.set_value();
      release.get_future().wait();
    });
  });
  holding.get_future().wait();
  auto other =
      std::async(std::launch::async, [&] { return store.sessions(std::nullopt, 0, UINT64_MAX); });
  const bool answered = other.wait_for(std::chrono::seconds(2)) == std::future_status::ready;
  release.set_value();
  slow.join();
  ASSERT_TRUE(answered) << "a query waited for the slow reader";
  EXPECT_EQ(other.get().size(), 1u);
}

// Given two nodes sailing with one boat id (two runs interleaving in time), the store flags the
// id; a boat's restart (runs one after the other) and an earlier run delivered beside the new
// one are not flagged.
TEST_F(StoreTest, TwoRunsOfOneIdAtOnceAreFlagged) {
  Store store(config());
  // A restart: run 1 for 10 s, then run 2; run 1's tail delivered late.
  for (std::uint64_t i = 1; i <= 10; ++i) store.enqueue(sample("r", 1, i, kT0 + i * kSecond));
  for (std::uint64_t i = 1; i <= 10; ++i)
    store.enqueue(sample("r", 2, i, kT0 + (20 + i) * kSecond));
  store.flush();
  EXPECT_TRUE(store.duplicate_ids().empty());
  // Two nodes named "d" at once, over the same 10 s.
  for (std::uint64_t i = 1; i <= 10; ++i) {
    store.enqueue(sample("d", 7, i, kT0 + i * kSecond));
    store.enqueue(sample("d", 8, i, kT0 + i * kSecond + kSecond / 50));
  }
  store.flush();
  const auto dups = store.duplicate_ids();
  ASSERT_EQ(dups.size(), 1u);
  EXPECT_EQ(dups[0].boat_id, "d");
  EXPECT_EQ(dups[0].boot_a, 7u);
  EXPECT_EQ(dups[0].boot_b, 8u);
}

// Given two nodes sailing as "tw" at once (25 Hz each, batches as they arrive), then the second
// node's run is recorded under its own id from the moment the overlap shows (its first second or
// so stays with the first node's), the first node's run stays whole under "tw", and after a
// restart of the shore the second run's resent samples still go to its own id.
TEST_F(StoreTest, TwoNodesUnderOneIdAreKeptApart) {
  const std::string alias = Store::duplicate_alias("tw", 0xabcdef12);
  EXPECT_EQ(alias, "tw-cdef12");
  EXPECT_EQ(Store::duplicate_alias(std::string(32, 'x'), 1), std::string(25, 'x') + "-000001");
  const auto both = [&](Store& store, std::uint64_t from, std::uint64_t to) {
    for (std::uint64_t i = from; i <= to; ++i) {
      store.enqueue(sample("tw", 0x7, i, kT0 + i * kSecond / 25));
      store.enqueue(sample("tw", 0xabcdef12, i, kT0 + i * kSecond / 25 + kSecond / 100));
      if (i % 6 == 0) store.flush();  // a batch per ~250 ms, as live
    }
    store.flush();
  };
  {
    Store store(config());
    both(store, 1, 250);  // 10 s
    EXPECT_EQ(store.count("tw") + store.count(alias), 500);
    EXPECT_GE(store.count(alias), 200) << "the second node's samples stayed under the boat's id";
    EXPECT_LE(store.count("tw"), 300);
    const auto sessions = store.sessions(std::nullopt, 0, UINT64_MAX);
    ASSERT_EQ(sessions.size(), 2u);
  }
  Store reopened(config());
  const auto before = reopened.count("tw");
  for (std::uint64_t i = 200; i <= 250; ++i)  // the second node resends its tail
    reopened.enqueue(sample("tw", 0xabcdef12, i, kT0 + i * kSecond / 25 + kSecond / 100));
  reopened.flush();
  EXPECT_EQ(reopened.count("tw"), before);
}

using test::fill_disk;
using test::SmallTmpfs;

// Given a shore whose disk fills up (a real small tmpfs), then commits back off exponentially
// instead of retrying the whole backlog every commit interval, the backlog stays bounded (later
// samples refused and counted, never acknowledged), health() says so; when space returns
// everything queued is committed; and at a stop with the disk still full, the samples it could
// not save are named on stderr.
TEST_F(StoreTest, FullDiskBacksOffBoundsTheBacklogAndSaysWhatIsLost) {
  const auto mnt = dir_ / "full";
  const SmallTmpfs tmpfs(mnt);
  if (!tmpfs.mounted)
    FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  auto c = config();
  c.path = (mnt / "s.db").string();
  c.max_backlog = 3000;
  c.max_retry_interval = std::chrono::milliseconds(1000);
  std::uint64_t seq = 0;
  {
    Store store(c);
    for (int i = 0; i < 100; ++i, ++seq)
      store.enqueue(sample("d", 5, seq + 1, kT0 + seq * kSecond));
    store.flush();
    ASSERT_EQ(store.count("d"), 100);
    fill_disk(mnt / "ballast");
    for (int round = 0; round < 20; ++round) {
      for (int i = 0; i < 1000; ++i, ++seq)
        store.enqueue(sample("d", 5, seq + 1, kT0 + seq * kSecond));
      std::this_thread::sleep_for(std::chrono::milliseconds(150));
    }
    const StoreHealth h = store.health();
    EXPECT_TRUE(h.failing) << h.last_error;
    EXPECT_FALSE(h.last_error.empty());
    // Bounded: at most max_backlog queued, and while an attempt runs as much again in the
    // writer's hands (health counts both); the rest of the 20 000 is counted as dropped.
    EXPECT_LE(h.backlog, 2 * 3000u);
    EXPECT_GE(h.dropped, 20000u - 2 * 3000u);
    // 3 s of failure: 20 ms doubling to 1 s is about 8 attempts (150 at a fixed 20 ms).
    EXPECT_LE(h.failed_commits, 12u);
    EXPECT_GE(h.failed_commits, 3u);
    // Space again: the backlog goes in (at the next attempt, within the 1 s cap).
    std::filesystem::remove(mnt / "ballast");
    for (int i = 0; i < 40 && store.health().failing; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    store.flush();
    EXPECT_FALSE(store.health().failing);
    EXPECT_EQ(store.health().backlog, 0u);
    // Everything not refused is stored.
    EXPECT_EQ(store.count("d"), static_cast<std::int64_t>(seq - store.health().dropped));
    // A second spell, and a stop during it.
    fill_disk(mnt / "ballast");
    for (int i = 0; i < 500; ++i, ++seq)
      store.enqueue(sample("d", 5, seq + 1, kT0 + seq * kSecond));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::testing::internal::CaptureStderr();
  }
  const std::string said = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("could not be saved"), std::string::npos) << said;
  EXPECT_NE(said.find("d run 0000000000000005 seq"), std::string::npos) << said;
  EXPECT_NE(said.find("session logs"), std::string::npos) << said;
}

// Given a full disk, wearable samples and GNSS fixes (which no boat can resend) are kept and
// retried like attitude, and all of them are stored once space comes back.
TEST_F(StoreTest, FullDiskKeepsWearablesFixesAndWindAndStoresThemLater) {
  const auto mnt = dir_ / "full";
  const SmallTmpfs tmpfs(mnt);
  if (!tmpfs.mounted)
    FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  auto c = config();
  c.path = (mnt / "s.db").string();
  c.max_retry_interval = std::chrono::milliseconds(200);
  Store store(c);
  store.enqueue(sample("w", 1, 1, kT0));
  store.flush();
  fill_disk(mnt / "ballast");
  constexpr int kN = 600;
  for (int i = 0; i < kN; ++i) {
    WearableSample w;
    w.athlete_id = "ann";
    w.seq = static_cast<std::uint64_t>(i + 1);
    w.t_utc_ns = kT0 + static_cast<std::uint64_t>(i) * kSecond / 5;
    w.gait = "walk";
    w.pose = "hand_held";
    store.enqueue(w);
    FixSample f;
    f.boat_id = "w";
    f.seq = static_cast<std::uint64_t>(i + 1);
    f.t_utc_ns = kT0 + static_cast<std::uint64_t>(i) * kSecond / 10;
    f.fix = "3d";
    f.lat_deg = 54.0 + i * 1e-6;
    f.lon_deg = 10.0;
    f.sog_m_s = 3.0;
    f.cog_deg = 0.0;
    store.enqueue(f);
    WindSample wind;
    wind.boat_id = "w";
    wind.t_utc_ns = f.t_utc_ns;
    wind.from_deg = 250.0 + (i % 7);
    wind.speed_m_s = 6.0;
    wind.source = "mwv_apparent";
    store.enqueue(wind);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  StoreHealth h = store.health();
  EXPECT_TRUE(h.failing) << "the full disk must fail the writes";
  EXPECT_EQ(h.wearable_backlog, static_cast<std::size_t>(kN));
  EXPECT_EQ(h.fix_backlog, static_cast<std::size_t>(kN));
  EXPECT_EQ(h.wind_backlog, static_cast<std::size_t>(kN));
  std::filesystem::remove(mnt / "ballast");
  for (int i = 0; i < 40 && store.health().failing; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  store.flush();
  h = store.health();
  EXPECT_FALSE(h.failing) << h.last_error;
  EXPECT_EQ(h.wearable_dropped + h.fixes_dropped + h.wind_dropped, 0u);
  const auto wind = store.wind("w", 0, UINT64_MAX, 100000);
  ASSERT_EQ(wind.size(), static_cast<std::size_t>(kN));
  EXPECT_EQ(wind[3].from_deg, 253.0);
  EXPECT_EQ(wind[3].source, "mwv_apparent");
  EXPECT_EQ(store.wind("w", 0, UINT64_MAX, 50).size(), 50u);  // thinned, first and last kept
  EXPECT_EQ(store.wind("w", 0, UINT64_MAX, 50).back().t_utc_ns, wind.back().t_utc_ns);
  EXPECT_EQ(store.wearable_track("ann", 0, UINT64_MAX, 100000).size(),
            static_cast<std::size_t>(kN));
  EXPECT_EQ(store.track("w", 0, UINT64_MAX, 100000).size(), static_cast<std::size_t>(kN));
}

}  // namespace
}  // namespace telltale::shore
