// fusion_cli steps / pdr on real files as they come: repeated time stamps are merged
// and counted in the JSON summary; time going backwards is one line naming file, line and
// column, exit status 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

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

TEST_F(StepsCli, TimeGoingBackwardsIsAnErrorNamingFileLineAndColumn) {
  write_walk("back.csv", 0, true);
  EXPECT_EQ(run("steps --in " + path("back.csv")), 2);
  // Row 100 is line 102 (header, 1-based); t_s is column 1.
  EXPECT_NE(read("err.txt").find(path("back.csv") + ":102:1: time goes backwards"),
            std::string::npos)
      << read("err.txt");
}

}  // namespace
