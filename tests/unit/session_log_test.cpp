// The boat's session log across runs: which earlier runs still need delivering, and how far
// each one goes on disk.
#include "session_log.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

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

}  // namespace
}  // namespace telltale::boat
