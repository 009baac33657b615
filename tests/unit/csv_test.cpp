#include "csv.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace telltale::io {
namespace {

class CsvTest : public ::testing::Test {
 protected:
  std::string write(const std::string& text) {
    path_ = (std::filesystem::temp_directory_path() /
             ("telltale_csv_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".csv"))
                .string();
    std::ofstream(path_) << text;
    return path_;
  }
  void TearDown() override { std::remove(path_.c_str()); }
  std::string path_;
};

std::string error_of(const std::string& path, std::vector<CsvColumn> cols) {
  try {
    (void)read_csv(path, cols, "t_s");
  } catch (const CsvError& e) {
    return e.what();
  }
  return "";
}

TEST_F(CsvTest, PicksColumnsByNameInAnyOrderAndIgnoresExtras) {
  const auto p = write("x,b,t_s,a\n9,2,0.5,1\n9,4,1.5,3\n");
  const auto t = read_csv(p, {{"t_s"}, {"a"}, {"b"}}, "t_s");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.col("a")[1], 3.0);
  EXPECT_DOUBLE_EQ(t.col("b")[0], 2.0);
  EXPECT_DOUBLE_EQ(t.col("t_s")[1], 1.5);
}

TEST_F(CsvTest, ErrorsNameFileLineAndColumn) {
  const auto expect_error = [this](const std::string& text, std::vector<CsvColumn> cols,
                                   const std::string& where_and_what) {
    const std::string p = write(text);
    EXPECT_EQ(error_of(p, std::move(cols)).rfind(p + ":" + where_and_what, 0), 0u)
        << "input: " << text;
  };
  expect_error("t_s,a\n0,1\n1,abc\n", {{"t_s"}, {"a"}}, "3:2: not a number in column 'a': 'abc'");
  expect_error("t_s,a\n0,1\n1,nan\n", {{"t_s"}, {"a"}}, "3:2: non-finite value in column 'a'");
  expect_error("t_s,b\n0,1\n", {{"t_s"}, {"a"}}, "1:0: missing column 'a'");
  expect_error("", {{"t_s"}}, "1:0: empty file (no header line)");
  expect_error("t_s\n", {{"t_s"}}, "2:0: no data rows");
  expect_error("t_s,a\n1,1\n0.5,1\n", {{"t_s"}, {"a"}}, "3:1: time not increasing");
  expect_error("t_s,a\n1,1,3\n", {{"t_s"}, {"a"}}, "2:3: expected 2 fields, found 3");
  expect_error("t_s,a\n1,2x\n", {{"t_s"}, {"a"}}, "2:2: not a number in column 'a': '2x'");
}

// Real phones write repeated time stamps: with TimeOrder::kNonDecreasing the rows are returned
// and counted; time going backwards stays an error naming file, line and column. The default
// (strict) order still refuses a repeated stamp.
TEST_F(CsvTest, RepeatedTimeStampsAcceptedAndCountedWhenAsked) {
  const auto p = write("t_s,a\n0,1\n0.01,2\n0.01,3\n0.01,4\n0.02,5\n0.02,6\n0.03,7\n");
  CsvReader r(p, {{"t_s"}, {"a"}}, "t_s", TimeOrder::kNonDecreasing);
  std::vector<double> row;
  std::vector<double> a;
  while (r.next(row)) a.push_back(row[1]);
  EXPECT_EQ(a, (std::vector<double>{1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(r.repeated_times(), 3u);
  const std::string strict = error_of(p, {{"t_s"}, {"a"}});
  EXPECT_EQ(strict.rfind(p + ":4:1: time not increasing", 0), 0u) << strict;
}

TEST_F(CsvTest, TimeGoingBackwardsStaysAnErrorWithRepeatedStampsAllowed) {
  const auto p = write("x,t_s,a\n0,0,1\n0,0.01,2\n0,0.01,3\n0,0.005,4\n");
  CsvReader r(p, {{"t_s"}, {"a"}}, "t_s", TimeOrder::kNonDecreasing);
  std::vector<double> row;
  std::string err;
  try {
    while (r.next(row)) {
    }
  } catch (const CsvError& e) {
    err = e.what();
  }
  EXPECT_EQ(err.rfind(p + ":5:2: time goes backwards", 0), 0u) << err;
}

TEST_F(CsvTest, MissingValuesWhereAllowed) {
  const auto p = write("t_s,h1_deg,h2_deg\n0,,1\n0.1,nan,2\n");
  const auto t = read_csv(
      p, {{"t_s"}, {"h1_deg", true, true}, {"h2_deg", true, true}, {"h3_deg", false, true}}, "t_s");
  EXPECT_TRUE(std::isnan(t.col("h1_deg")[0]));
  EXPECT_TRUE(std::isnan(t.col("h1_deg")[1]));
  EXPECT_TRUE(std::isnan(t.col("h3_deg")[0]));
  EXPECT_DOUBLE_EQ(t.col("h2_deg")[1], 2.0);
}

TEST_F(CsvTest, WriterRoundTrips) {
  const auto p = write("");
  {
    CsvWriter w(p, {"t_s", "v"});
    w.row({0.1, 1.0 / 3.0});
    w.row({0.2, std::nan("")});
    w.close();
  }
  const auto t = read_csv(p, {{"t_s"}, {"v", true, true}}, "t_s");
  EXPECT_NEAR(t.col("v")[0], 1.0 / 3.0, 1e-9);
  EXPECT_TRUE(std::isnan(t.col("v")[1]));
}

}  // namespace
}  // namespace telltale::io
