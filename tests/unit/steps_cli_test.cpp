// fusion_cli steps / pdr on real files as they come: repeated time stamps are merged
// and counted in the JSON summary; time going backwards is one line naming file, line and
// column, exit status 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fusion_cli_fixture.hpp"

namespace {

namespace fs = std::filesystem;

class StepsCli : public telltale::testing::FusionCliTest {
 protected:
  /// 10 s of a phone at 50 Hz walking at 2 steps/s (vertical +-2 m/s^2); every `every`-th row
  /// is written twice with the same stamp (a batch the OS stamped once).
  void write_walk(const std::string& name, int every, bool backwards_at_row_100 = false) const {
    std::ofstream out(path(name));
    out << "t_s,ax_m_s2,ay_m_s2,az_m_s2\n";
    for (int n = 0; n < 500; ++n) {
      double t = n * 0.02;
      if (backwards_at_row_100 && n == 100) t -= 0.05;
      const double walking = (t > 2.0 && t < 8.0) ? 1.0 : 0.0;
      const double az = 9.81 - walking * 2.0 * std::cos(2.0 * M_PI * 2.0 * (t - 2.0));
      out << t << ",0.1,0.2," << az << "\n";
      if (every > 0 && n % every == 0) out << t << ",0.1,0.2," << az + 0.01 << "\n";
    }
  }
};

TEST_F(StepsCli, RepeatedTimeStampsAreMergedAndCounted) {
  write_walk("rep.csv", 10);  // rows 0, 10, ..., 490 repeated: 50 repeats
  ASSERT_EQ(run("steps --in " + path("rep.csv") + " --mount phone"), 0) << read("err.txt");
  const std::string out = read("out.txt");
  EXPECT_NE(out.find("\"repeated_stamps\": 50"), std::string::npos) << out;
  EXPECT_NE(out.find("\"samples\": 500"), std::string::npos) << out;
  EXPECT_NE(out.find("\"steps\": 12"), std::string::npos) << out;  // 6 s at 2 steps/s
  ASSERT_EQ(run("pdr --in " + path("rep.csv") + " --height-m 1.75 --out " + path("track.csv")), 0)
      << read("err.txt");
  EXPECT_NE(read("out.txt").find("\"repeated_stamps\": 50"), std::string::npos) << read("out.txt");
}

// A walk (2-8 s, 12 steps), a stand, then the phone taken out and turned up to be read (11-14 s:
// tilted through 120 deg while the hand shakes at 2 Hz): the shakes are refused and counted in
// the summary. With the rule off (a foot's peak-valley) every shake is a step, so the test can
// fail.
TEST_F(StepsCli, StepsRefusedWhileThePhoneIsHandledAreCounted) {
  {
    std::ofstream out(path("handled.csv"));
    out << "t_s,ax_m_s2,ay_m_s2,az_m_s2\n";
    for (int n = 0; n < 800; ++n) {
      const double t = n * 0.02;
      const double walking = (t > 2.0 && t < 8.0) ? 1.0 : 0.0;
      double f = 9.81 - walking * 2.0 * std::cos(2.0 * M_PI * 2.0 * (t - 2.0));
      const double in_hand = std::clamp(t - 11.0, 0.0, 3.0);
      if (in_hand > 0.0 && in_hand < 3.0) f += 3.0 * std::sin(2.0 * M_PI * 2.0 * t);
      const double tilt = (120.0 * M_PI / 180.0) * in_hand / 3.0;
      out << t << "," << f * std::sin(tilt) << ",0," << f * std::cos(tilt) << "\n";
    }
  }
  ASSERT_EQ(run("steps --in " + path("handled.csv") + " --mount phone"), 0) << read("err.txt");
  std::string out = read("out.txt");
  const auto number = [&out](const std::string& key) {
    const auto at = out.find("\"" + key + "\": ");
    return at == std::string::npos ? -1 : std::atoi(out.c_str() + at + key.size() + 4);
  };
  EXPECT_EQ(number("steps"), 12) << out;  // the walk's
  EXPECT_EQ(number("refused_handling"), 6) << out;
  ASSERT_EQ(run("steps --in " + path("handled.csv") + " --mount foot --method peak-valley"), 0);
  out = read("out.txt");
  EXPECT_EQ(number("refused_handling"), 0) << out;
}

TEST_F(StepsCli, TimeGoingBackwardsIsAnErrorNamingFileLineAndColumn) {
  write_walk("back.csv", 0, true);
  EXPECT_EQ(run("steps --in " + path("back.csv")), 2);
  // Row 100 is line 102 (header, 1-based); t_s is column 1.
  EXPECT_NE(read("err.txt").find(path("back.csv") + ":102:1: time goes backwards"),
            std::string::npos)
      << read("err.txt");
}

// Given a trial laid out as the IPOL healthy-gait folder (README: steps reported inside the
// U-turn are left out; the annotated steps are those outside it): a lower-back sensor walking 12
// steps at 2 steps/s, every heel strike annotated, two of them inside the U-turn. When
// steps-eval scores it, then the README column compares the 10 steps found outside the U-turn
// with the 10 annotated outside it (100 %), and the column against every annotated step says
// 83 %. (The table once printed the latter as the README rule.)
TEST_F(StepsCli, IpolReadmeRuleLeavesTheUTurnOutOfTheAnnotationsToo) {
  namespace fs = std::filesystem;
  fs::create_directories(path("data/ipol_gait"));
  std::ofstream csv(path("data/ipol_gait/9-1_lb.imu.csv"));
  csv << "t_s,ax_m_s2,ay_m_s2,az_m_s2,gx_rad_s,gy_rad_s,gz_rad_s\n";
  // Walking from 2 s to 7.875 s: the trunk's vertical force -1.5 cos(2 pi 2 t) peaks once a
  // step, at the loading after each heel strike: 2.25, 2.75, ..., 7.75 s; the last loading
  // settles into standing (a walk that stopped in mid-fall, at a valley, would end with the
  // closing heel strike that catches it: one more step).
  for (int n = 0; n < 1000; ++n) {
    const double t = n / 100.0;
    const double walking = (t >= 2.0 && t < 7.875) ? 1.0 : 0.0;
    const double az = 9.81 - walking * 1.5 * std::cos(2.0 * M_PI * 2.0 * (t - 2.0));
    csv << t << ",0.1,0.2," << az << ",0,0,0\n";
  }
  csv.close();
  std::string left, right;
  for (int k = 0; k < 12; ++k) {
    const int hs = 225 + 50 * k;  // sample index (100 Hz)
    std::string& foot = k % 2 == 0 ? left : right;
    foot += std::string(foot.empty() ? "" : ", ") + "[" + std::to_string(hs - 40) + ", " +
            std::to_string(hs) + "]";
  }
  // U-turn 4.5-5.5 s: the heel strikes at 4.75 and 5.25 s are inside it.
  write("data/ipol_gait/9-1.json",
        "{\"TrialBoundaries\": [185, 775], \"UTurnBoundaries\": [450, 550], \"LeftFootEvents\": [" +
            left + "], \"RightFootEvents\": [" + right + "]}");
  ASSERT_EQ(run("steps-eval --tables ipol --data " + path("data")), 0) << read("err.txt");
  const std::string out = read("out.txt");
  const auto row = out.find("| 9-1_lb | 10 / 12 |");
  ASSERT_NE(row, std::string::npos) << out;
  const std::string line = out.substr(row, out.find('\n', row) - row);
  // The gait-phase column, the lower back's default (fusion_cli steps --mount body), found by
  // its header (the table's columns: file, annotated, past the end, then one per method).
  const auto cells = [](const std::string& l) {
    std::vector<std::string> c;
    std::size_t from = l.find('|');
    while (from != std::string::npos) {
      const std::size_t to = l.find('|', from + 1);
      if (to == std::string::npos) break;
      c.push_back(l.substr(from + 1, to - from - 1));
      from = to;
    }
    return c;
  };
  const auto header_at = out.rfind("| file |", row);
  ASSERT_NE(header_at, std::string::npos) << out;
  const auto header = cells(out.substr(header_at, out.find('\n', header_at) - header_at));
  const auto column = std::find(header.begin(), header.end(), " gait-phase ") - header.begin();
  const auto row_cells = cells(line);
  ASSERT_LT(static_cast<std::size_t>(column), row_cells.size()) << out;
  EXPECT_EQ(row_cells[static_cast<std::size_t>(column)], " 10 (100 / 83) ") << line;
}

// No simulated walk to score is a usage error, not a table that reads its first element.
// Seen failing before the check: `steps-eval --loops 0 --tables pdr` ended in a segmentation
// fault (status -1 here), `--people 0` printed -nan.
// `pdr --mount trunk` on a simulated belt sensor's walk (gait-sim body-walk): one track row per
// step and the summary's distance within 12 % of the walk (the simulated person's bounce moves the
// pendulum's step by up to 10 %: docs/pdr.md); a mount the command does not know is refused,
// naming the ones it does.
TEST_F(StepsCli, TrunkMountMeasuresTheWalk) {
  ASSERT_EQ(run("gait-sim body-walk --seed 3 --out " + path("belt.csv") + " --truth " +
                path("belt_truth.csv")),
            0)
      << read("err.txt");
  ASSERT_EQ(run("pdr --in " + path("belt.csv") + " --mount trunk --height-m 1.75 --out " +
                path("belt_track.csv")),
            0)
      << read("err.txt");
  const std::string out = read("out.txt");
  const auto at = out.find("\"distance_m\": ");
  ASSERT_NE(at, std::string::npos) << out;
  const double distance = std::strtod(out.c_str() + at + 14, nullptr);
  // The truth's last row: t_s,x_m,y_m,heading_deg,distance_m,...
  std::ifstream truth(path("belt_truth.csv"));
  std::string line, last;
  while (std::getline(truth, line))
    if (!line.empty()) last = line;
  std::vector<double> cols;
  for (std::size_t a = 0; a <= last.size();) {
    const std::size_t b = std::min(last.find(',', a), last.size());
    cols.push_back(std::strtod(last.substr(a, b - a).c_str(), nullptr));
    a = b + 1;
  }
  ASSERT_GE(cols.size(), 5u) << last;
  EXPECT_NEAR(distance, cols[4], 0.12 * cols[4]) << out;
  std::ifstream track(path("belt_track.csv"));
  std::size_t rows = 0;
  while (std::getline(track, line)) rows += line.empty() ? 0u : 1u;
  EXPECT_GT(rows, 50u);
  EXPECT_NE(
      run("pdr --in " + path("belt.csv") + " --mount belly --height-m 1.75 --out " + path("x.csv")),
      0);
  EXPECT_NE(read("err.txt").find("trunk"), std::string::npos) << read("err.txt");
}

TEST_F(StepsCli, EvalRefusesNoSimulatedWalks) {
  for (const char* args :
       {"--loops 0 --tables pdr", "--loops -3 --tables ipin", "--people 0 --tables gait"}) {
    const int rc = run(std::string("steps-eval --data ") + path("none") + " " + args);
    EXPECT_NE(rc, 0) << args;
    EXPECT_NE(rc, -1) << args << ": did not exit";
    EXPECT_NE(read("err.txt").find(std::string(args).substr(0, 7)), std::string::npos)
        << args << ": " << read("err.txt");
  }
}

}  // namespace
