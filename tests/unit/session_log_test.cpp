// The boat's session log across runs: which earlier runs still need delivering, and how far
// each one goes on disk.
#include "session_log.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

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

/// A private mount namespace for this test process (root only), so tmpfs mounts with a size limit
/// or read-only ones stay invisible to everything else. False where that is not allowed.
bool private_mounts() {
  static const bool ok = [] {
    if (::geteuid() != 0 || ::unshare(CLONE_NEWNS) != 0) return false;
    return ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0;
  }();
  return ok;
}

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
  if (!mount_tmpfs("size=256k,mode=0755")) FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
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
  if (!mount_tmpfs("size=64k", MS_RDONLY)) FAIL() << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  EXPECT_THROW(SessionLog({dir_, "ro", 0x1, 100000, 1ULL << 30}), std::runtime_error);
}

}  // namespace
}  // namespace telltale::boat
