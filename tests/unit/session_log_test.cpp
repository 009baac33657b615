// The boat's session log across runs: which earlier runs still need delivering, and how far
// each one goes on disk; both record kinds (attitude, GNSS fixes); the backfill's stop.
#include "session_log.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "backfill.hpp"
#include "small_tmpfs.hpp"

namespace telltale::boat {
namespace {

constexpr std::chrono::hours kWeek{24 * 7};

class SessionLogRuns : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tt_session_log_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  void write_run(const std::string& boat, std::uint64_t boot, std::uint64_t records,
                 std::uint64_t per_file = 100000) {
    SessionLog log({dir_, boat, boot, per_file, 1ULL << 30});
    for (std::uint64_t seq = 1; seq <= records; ++seq) {
      LogRecord r;
      r.seq = seq;
      r.t_utc_ns = seq * 40'000'000;
      ASSERT_TRUE(log.append(r));
    }
    log.flush();
  }

  std::filesystem::path dir_;
};

TEST_F(SessionLogRuns, EarlierRunsOfThisBoatOnlyUntilDelivered) {
  write_run("a", 0x11, 30, 7);  // five files: 1, 8, 15, 22, 29
  write_run("a", 0x22, 5);
  write_run("a-b", 0x33, 5);  // another boat whose id starts with this one's
  write_run("a", 0x44, 3);    // the current run
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, kWeek), (std::vector<std::uint64_t>{0x11, 0x22}));
  EXPECT_EQ(undelivered_runs(dir_, "a-b", 0x99, kWeek), (std::vector<std::uint64_t>{0x33}));
  EXPECT_EQ(SessionLogReader(dir_, "a", 0x11).last_seq(), 30u);
  EXPECT_EQ(SessionLogReader(dir_, "a", 0x22).last_seq(), 5u);
  EXPECT_EQ(SessionLogReader(dir_, "a", 0x55).last_seq(), 0u);  // no such run

  mark_delivered(dir_, "a", 0x11);
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, kWeek), (std::vector<std::uint64_t>{0x22}));
  // A marker whose run the disk policy deleted goes too.
  for (const auto& e : std::filesystem::directory_iterator(dir_))
    if (e.path().filename().string().rfind("a-0000000000000011-", 0) == 0)
      std::filesystem::remove(e.path());
  ASSERT_TRUE(std::filesystem::exists(dir_ / "a-0000000000000011.delivered"));
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, kWeek), (std::vector<std::uint64_t>{0x22}));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "a-0000000000000011.delivered"));
  // A run last written to before the age limit is not offered.
  const auto old_time = std::filesystem::file_time_type::clock::now() - std::chrono::hours(200);
  for (const auto& e : std::filesystem::directory_iterator(dir_))
    if (e.path().filename().string().rfind("a-0000000000000022-", 0) == 0)
      std::filesystem::last_write_time(e.path(), old_time);
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, kWeek), std::vector<std::uint64_t>{});
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, std::chrono::hours(300)),
            (std::vector<std::uint64_t>{0x22}));
  // Files that only look like logs are not runs.
  std::ofstream(dir_ / "a-zzzzzzzzzzzzzzzz-000000000001.tlog") << "x";
  std::ofstream(dir_ / "a-0000000000000066.tlog") << "x";
  EXPECT_EQ(undelivered_runs(dir_, "a", 0x44, std::chrono::hours(300)),
            (std::vector<std::uint64_t>{0x22}));
}

using test::private_mounts;

class SessionLogFaults : public SessionLogRuns {
 protected:
  void TearDown() override {
    ::umount2(dir_.c_str(), MNT_DETACH);
    SessionLogRuns::TearDown();
  }
  /// A real small filesystem at dir_ (tmpfs, `options` e.g. "size=256k" or "ro").
  bool mount_tmpfs(const std::string& options, unsigned long flags = 0) {
    std::filesystem::create_directories(dir_);
    return private_mounts() && ::mount("tmpfs", dir_.c_str(), "tmpfs", flags, options.c_str()) == 0;
  }
  static LogRecord record(std::uint64_t seq) {
    LogRecord r;
    r.seq = seq;
    r.t_utc_ns = seq * 40'000'000;
    r.heel_deg = static_cast<double>(seq) * 0.01;
    return r;
  }
};

// Given a log on a small real filesystem, when a ballast file fills the disk for a while and is
// then removed, then every record appended before, during and after the spell is read back in
// order (none torn, none off the record grid).
// Given a healthy disk, records buffered between two flushes are held in memory but the log is
// not failing (every boat's first status used to read "SESSION LOG FAILING ()" for that).
TEST_F(SessionLogRuns, BufferedRecordsAreNotAFailure) {
  SessionLog log({dir_, "ok", 0x5, 100000, 1ULL << 30});
  LogRecord r;
  r.seq = 1;
  r.t_utc_ns = 40'000'000;
  ASSERT_TRUE(log.append(r));
  EXPECT_EQ(log.health().pending_records, 1u);
  EXPECT_FALSE(log.health().failing());
  ASSERT_TRUE(log.flush());
  EXPECT_EQ(log.health().pending_records, 0u);
}

TEST_F(SessionLogFaults, DiskFullSpellLosesNothingAndReportsIt) {
  if (!mount_tmpfs("size=256k,mode=0755"))
    FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  const auto ballast = dir_ / "ballast";
  {
    // Fill the filesystem, then give back a little over one page.
    const int fd = ::open(ballast.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    std::vector<char> block(4096, 'x');
    while (::write(fd, block.data(), block.size()) > 0) {
    }
    ::close(fd);
  }
  std::filesystem::resize_file(ballast, std::filesystem::file_size(ballast) - 6000);
  SessionLog log({dir_, "full", 0xf1, 100000, 1ULL << 30});
  std::uint64_t seq = 0;
  for (; seq < 400; ++seq) {  // 38 KB: the disk fills after about 60 records
    (void)log.append(record(seq + 1));
    if (seq % 10 == 9) log.flush();
  }
  // The spell is seen and reported: records held in memory, the error named.
  const SessionLogHealth during = log.health();
  EXPECT_GT(during.pending_records, 0u);
  EXPECT_TRUE(during.failing());
  EXPECT_GT(during.write_errors, 0u);
  EXPECT_NE(during.last_error.find("No space"), std::string::npos) << during.last_error;
  std::filesystem::remove(ballast);  // the spell ends
  for (; seq < 600; ++seq) {
    (void)log.append(record(seq + 1));
    if (seq % 10 == 9) log.flush();
  }
  EXPECT_TRUE(log.flush());
  EXPECT_EQ(log.health().pending_records, 0u);
  EXPECT_EQ(log.health().dropped_records, 0u);
  EXPECT_TRUE(log.health().last_error.empty());
  EXPECT_FALSE(log.health().failing());
  SessionLogReader reader(dir_, "full", 0xf1);
  const auto back = reader.read(1, 600);
  ASSERT_EQ(back.size(), 600u);
  for (std::uint64_t i = 0; i < back.size(); ++i) ASSERT_EQ(back[i].seq, i + 1);
  EXPECT_EQ(reader.last_seq(), 600u);
}

// Given a log file with a torn record in the middle (a crash or a full disk mid-write), the
// reader finds every intact record after it.
TEST_F(SessionLogRuns, ReaderResynchronisesAfterATornRecord) {
  write_run("torn", 0x7, 10);
  const auto file = dir_ / "torn-0000000000000007-000000000001.tlog";
  ASSERT_TRUE(std::filesystem::exists(file));
  {
    std::ofstream out(file, std::ios::binary | std::ios::app);
    unsigned char buf[kLogRecordBytes];
    encode_record(LogRecord{.seq = 11, .t_utc_ns = 11}, buf);
    out.write(reinterpret_cast<const char*>(buf), 50);  // torn
    for (std::uint64_t seq = 11; seq <= 20; ++seq) {
      encode_record(LogRecord{.seq = seq, .t_utc_ns = seq}, buf);
      out.write(reinterpret_cast<const char*>(buf), sizeof buf);
    }
  }
  SessionLogReader reader(dir_, "torn", 0x7);
  const auto all = reader.read(1, 20);
  ASSERT_EQ(all.size(), 20u);
  for (std::uint64_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].seq, i + 1);
  const auto part = reader.read(12, 15);
  ASSERT_EQ(part.size(), 4u);
  EXPECT_EQ(part.front().seq, 12u);
  EXPECT_EQ(reader.last_seq(), 20u);
}

// Given a log directory that exists but cannot be written (a read-only mount), the log refuses
// to open: a boat must not say "ready" and then sail without a log.
TEST_F(SessionLogFaults, ReadOnlyDirectoryIsRefused) {
  if (!mount_tmpfs("size=64k", MS_RDONLY))
    FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  EXPECT_THROW(SessionLog({dir_, "ro", 0x1, 100000, 1ULL << 30}), std::runtime_error);
}

// --- GNSS fixes: the same log, another record kind --------------------------------------------

FixRecord fix_record(std::uint64_t seq) {
  FixRecord r;
  r.seq = seq;
  r.t_utc_ns = 1'700'000'000'000'000'000ULL + seq * 100'000'000;
  r.gnss_utc_ns = r.t_utc_ns - 250'000'000;
  r.lat_deg = 54.3 + static_cast<double>(seq) * 1e-5;
  r.lon_deg = 10.1 - static_cast<double>(seq) * 1e-5;
  r.sog_m_s = 3.5;
  r.cog_deg = static_cast<double>(seq % 360);
  r.fix = 3;
  r.satellites = 11;
  r.hdop = 0.9f;
  return r;
}

bool same_fix(const FixRecord& a, const FixRecord& b) {
  return a.seq == b.seq && a.t_utc_ns == b.t_utc_ns && a.gnss_utc_ns == b.gnss_utc_ns &&
         a.lat_deg == b.lat_deg && a.lon_deg == b.lon_deg && a.sog_m_s == b.sog_m_s &&
         a.cog_deg == b.cog_deg && a.fix == b.fix && a.satellites == b.satellites &&
         a.hdop == b.hdop;
}

// Given fixes appended across several files beside the attitude of the same run, every fix reads
// back bit for bit, and neither kind's reader sees the other's records.
TEST_F(SessionLogRuns, FixesRoundTripBesideTheAttitude) {
  write_run("fx", 0x21, 12, 5);
  {
    FixLog log({dir_, "fx", 0x21, 7, 1ULL << 30});  // three files: 1, 8, 15
    for (std::uint64_t seq = 1; seq <= 20; ++seq) ASSERT_TRUE(log.append(fix_record(seq)));
    ASSERT_TRUE(log.flush());
  }
  ASSERT_TRUE(std::filesystem::exists(dir_ / "fx-0000000000000021-000000000008.tfix"));
  FixLogReader fixes(dir_, "fx", 0x21);
  const auto back = fixes.read(1, 20);
  ASSERT_EQ(back.size(), 20u);
  for (std::uint64_t i = 0; i < back.size(); ++i)
    EXPECT_TRUE(same_fix(back[i], fix_record(i + 1))) << "seq " << i + 1;
  // A NaN position (no fix) survives as NaN.
  {
    FixRecord none = fix_record(1);
    none.lat_deg = none.lon_deg = none.sog_m_s = none.cog_deg = std::nan("");
    none.fix = 0;
    unsigned char frame[kLogRecordBytes];
    encode_record(none, frame);
    const auto got = decode_fix_record(frame);
    ASSERT_TRUE(got);
    EXPECT_TRUE(std::isnan(got->lat_deg) && std::isnan(got->cog_deg));
    // A fix frame is not an attitude frame (its own magic), and the reverse.
    EXPECT_FALSE(decode_record(frame));
    encode_record(LogRecord{.seq = 1, .t_utc_ns = 1}, frame);
    EXPECT_FALSE(decode_fix_record(frame));
  }
  EXPECT_EQ(fixes.last_seq(), 20u);
  EXPECT_EQ(fixes.read(9, 16).size(), 8u);
  EXPECT_EQ(SessionLogReader(dir_, "fx", 0x21).last_seq(), 12u);
  EXPECT_EQ(SessionLogReader(dir_, "fx", 0x21).read(1, 100).size(), 12u);
  // Each kind is delivered and marked on its own.
  EXPECT_EQ(undelivered_runs<FixCodec>(dir_, "fx", 0x99, kWeek), std::vector<std::uint64_t>{0x21});
  mark_delivered(dir_, "fx", 0x21);
  EXPECT_EQ(undelivered_runs(dir_, "fx", 0x99, kWeek), std::vector<std::uint64_t>{});
  EXPECT_EQ(undelivered_runs<FixCodec>(dir_, "fx", 0x99, kWeek), std::vector<std::uint64_t>{0x21});
  mark_delivered<FixCodec>(dir_, "fx", 0x21);
  EXPECT_EQ(undelivered_runs<FixCodec>(dir_, "fx", 0x99, kWeek), std::vector<std::uint64_t>{});
}

// Given a fix file with a torn record in the middle, the reader finds every intact fix after it.
TEST_F(SessionLogRuns, FixReaderResynchronisesAfterATornRecord) {
  {
    FixLog log({dir_, "tf", 0x8, 100000, 1ULL << 30});
    for (std::uint64_t seq = 1; seq <= 10; ++seq) ASSERT_TRUE(log.append(fix_record(seq)));
  }
  const auto file = dir_ / "tf-0000000000000008-000000000001.tfix";
  ASSERT_TRUE(std::filesystem::exists(file));
  {
    std::ofstream out(file, std::ios::binary | std::ios::app);
    unsigned char buf[kLogRecordBytes];
    encode_record(fix_record(11), buf);
    out.write(reinterpret_cast<const char*>(buf), 61);  // torn
    for (std::uint64_t seq = 11; seq <= 20; ++seq) {
      encode_record(fix_record(seq), buf);
      out.write(reinterpret_cast<const char*>(buf), sizeof buf);
    }
  }
  FixLogReader reader(dir_, "tf", 0x8);
  const auto all = reader.read(1, 20);
  ASSERT_EQ(all.size(), 20u);
  for (std::uint64_t i = 0; i < all.size(); ++i) EXPECT_TRUE(same_fix(all[i], fix_record(i + 1)));
  EXPECT_EQ(reader.read(12, 15).size(), 4u);
  EXPECT_EQ(reader.last_seq(), 20u);
}

// Given both kinds in one directory under one budget, the oldest files go first whatever their
// kind, and neither log loses the file it is writing to the other's deletions.
TEST_F(SessionLogRuns, OneDiskBudgetOverBothKinds) {
  // An earlier run of each kind, made old.
  write_run("bd", 0x1, 50, 10);  // five attitude files of 960 bytes
  {
    FixLog old({dir_, "bd", 0x1, 10, 1ULL << 30});
    for (std::uint64_t seq = 1; seq <= 50; ++seq) ASSERT_TRUE(old.append(fix_record(seq)));
  }
  const auto old_time = std::filesystem::file_time_type::clock::now() - std::chrono::hours(5);
  for (const auto& e : std::filesystem::directory_iterator(dir_))
    std::filesystem::last_write_time(e.path(), old_time);
  // The current run: a budget of 6 files of 960 bytes (one reserved for the file being opened).
  constexpr std::uint64_t kBudget = 6 * 960;
  SessionLog att({dir_, "bd", 0x2, 10, kBudget});
  FixLog fixes({dir_, "bd", 0x2, 10, kBudget});
  for (std::uint64_t seq = 1; seq <= 35; ++seq) {
    LogRecord r;
    r.seq = seq;
    r.t_utc_ns = seq;
    ASSERT_TRUE(att.append(r));
    ASSERT_TRUE(fixes.append(fix_record(seq)));
    att.flush();
    fixes.flush();
  }
  std::uintmax_t total = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir_)) total += e.file_size();
  EXPECT_LE(total, kBudget + 2 * 960) << "the budget, give or take the files being filled";
  EXPECT_GT(att.bytes_deleted() + fixes.bytes_deleted(), 0u);
  // The earlier run's files went first, of both kinds; the current run is whole in both.
  EXPECT_EQ(SessionLogReader(dir_, "bd", 0x1).read(1, 50).size(), 0u);
  EXPECT_EQ(FixLogReader(dir_, "bd", 0x1).read(1, 50).size(), 0u);
  EXPECT_EQ(FixLogReader(dir_, "bd", 0x2).read(31, 35).size(), 5u);
  EXPECT_EQ(SessionLogReader(dir_, "bd", 0x2).read(31, 35).size(), 5u);
}

// Given a budget too small for both kinds' open files, each log still keeps the file the other is
// writing: a deleted file takes what is written to it afterwards with it, without an error (the
// writer's descriptor stays valid), so that loss would be silent.
TEST_F(SessionLogRuns, NeitherKindDeletesTheFileTheOtherIsWriting) {
  constexpr std::uint64_t kPerFile = 4;
  constexpr std::uint64_t kBudget = kPerFile * kLogRecordBytes;  // one file
  FixLog fixes({dir_, "nd", 0x3, kPerFile, kBudget});
  for (std::uint64_t seq = 1; seq <= 3; ++seq) ASSERT_TRUE(fixes.append(fix_record(seq)));
  ASSERT_TRUE(fixes.flush());
  // The attitude log opens its first file: over budget with the fix file's 3 records.
  SessionLog att({dir_, "nd", 0x3, kPerFile, kBudget});
  for (std::uint64_t seq = 1; seq <= 3; ++seq) {
    LogRecord r;
    r.seq = seq;
    r.t_utc_ns = seq * 40'000'000;
    ASSERT_TRUE(att.append(r));
  }
  ASSERT_TRUE(att.flush());
  // And the fix log opens its second file: over budget with both.
  for (std::uint64_t seq = 4; seq <= 6; ++seq) ASSERT_TRUE(fixes.append(fix_record(seq)));
  ASSERT_TRUE(fixes.flush());
  EXPECT_EQ(SessionLogReader(dir_, "nd", 0x3).read(1, 3).size(), 3u);
  EXPECT_EQ(FixLogReader(dir_, "nd", 0x3).read(5, 6).size(), 2u);
  // What the budget could take went: the fix log's first file, no longer written.
  EXPECT_EQ(FixLogReader(dir_, "nd", 0x3).read(1, 4).size(), 0u);
}

// Given a run that published no fix (no receiver, or no data from it), the stop's drain of the
// fixes returns at once: the shore sends no fix receipt for a run it has no fix of, and waiting
// for one held every such boat's stop for 3 s.
TEST_F(SessionLogRuns, DrainWithNothingPublishedDoesNotWait) {
  FixBackfiller backfiller({0x5, 50, 2500, std::chrono::milliseconds(5000)},
                           FixLogReader(dir_, "nf", 0x5), [](const FixRecord&) { return true; });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(backfiller.drain(std::chrono::seconds(3), std::chrono::seconds(10)));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(500));
}

// Given a fix log on a small real filesystem, when the disk fills for a while and is then given
// back, every fix appended before, during and after the spell reads back in order: the fixes
// were held in memory and written later.
TEST_F(SessionLogFaults, FixesHeldWhileTheDiskIsFullAndWrittenLater) {
  if (!mount_tmpfs("size=256k,mode=0755"))
    FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  const auto ballast = dir_ / "ballast";
  {
    const int fd = ::open(ballast.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    std::vector<char> block(4096, 'x');
    while (::write(fd, block.data(), block.size()) > 0) {
    }
    ::close(fd);
  }
  std::filesystem::resize_file(ballast, std::filesystem::file_size(ballast) - 6000);
  FixLog log({dir_, "ff", 0xf2, 100000, 1ULL << 30});
  std::uint64_t seq = 0;
  for (; seq < 400; ++seq) {
    (void)log.append(fix_record(seq + 1));
    if (seq % 10 == 9) log.flush();
  }
  const SessionLogHealth during = log.health();
  EXPECT_GT(during.pending_records, 0u);
  EXPECT_TRUE(during.failing());
  EXPECT_NE(during.last_error.find("No space"), std::string::npos) << during.last_error;
  std::filesystem::remove(ballast);
  for (; seq < 600; ++seq) {
    (void)log.append(fix_record(seq + 1));
    if (seq % 10 == 9) log.flush();
  }
  EXPECT_TRUE(log.flush());
  EXPECT_FALSE(log.health().failing());
  EXPECT_EQ(log.health().dropped_records, 0u);
  FixLogReader reader(dir_, "ff", 0xf2);
  const auto back = reader.read(1, 600);
  ASSERT_EQ(back.size(), 600u);
  for (std::uint64_t i = 0; i < back.size(); ++i) ASSERT_TRUE(same_fix(back[i], fix_record(i + 1)));
}

}  // namespace
}  // namespace telltale::boat
