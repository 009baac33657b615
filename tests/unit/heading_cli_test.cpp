// fusion_cli heading / heading-sim / heading-eval end to end (SPEC section 6): the binary is run
// as analysts and scripts run it, files in a fresh temporary directory.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "csv.hpp"
#include "fusion_cli_fixture.hpp"
#include "telltale/fusion/angles.hpp"

namespace {

namespace fs = std::filesystem;

class HeadingCli : public telltale::testing::FusionCliTest {
 protected:
};

TEST_F(HeadingCli, SimulateThenFuseMatchesTruth) {
  // Given a simulated bias-step run written by heading-sim
  ASSERT_EQ(
      run("heading-sim dinghy-bias --seed 3 --out " + path("H.csv") + " --truth " + path("T.csv")),
      0)
      << read("err.txt");
  // When fusion_cli heading fuses it with the sensors' latencies
  ASSERT_EQ(
      run("heading --in " + path("H.csv") + " --out " + path("F.csv") + " --latency-s 0,0.05,0.1"),
      0)
      << read("err.txt");
  EXPECT_NE(read("out.txt").find("\"samples\": 2401"), std::string::npos) << read("out.txt");
  // Then F.csv starts with t_s,heading_deg and follows the truth within 0.3 deg RMS
  EXPECT_EQ(read("F.csv").rfind("t_s,heading_deg,", 0), 0u);
  const auto f =
      telltale::io::read_csv(path("F.csv"), {{"t_s"}, {"heading_deg"}, {"sensors_in_use"}});
  const auto t = telltale::io::read_csv(path("T.csv"), {{"t_s"}, {"heading_deg"}});
  ASSERT_EQ(f.rows(), t.rows());
  double sq = 0.0;
  int excluded_rows = 0;
  for (std::size_t k = 20; k < f.rows(); ++k) {
    const double e =
        telltale::fusion::wrap_180_deg(f.col("heading_deg")[k] - t.col("heading_deg")[k]);
    sq += e * e;
    const auto mask = static_cast<unsigned>(f.col("sensors_in_use")[k]);
    excluded_rows += (t.col("t_s")[k] > 61.0 && t.col("t_s")[k] < 179.0 && (mask & 2u)) ? 1 : 0;
  }
  EXPECT_LT(std::sqrt(sq / static_cast<double>(f.rows() - 20)), 0.3);
  EXPECT_EQ(excluded_rows, 0);  // the biased sensor 2 is never in use during its fault
}

TEST_F(HeadingCli, EveryMethodRunsAndUnknownOnesAreUsageErrors) {
  write("H.csv", "t_s,h1_deg,h2_deg\n0,359.9,\n0.1,nan,0.1\n0.2,0.2,0.3\n");
  for (const char* m : {"closed-loop", "closed-loop-paper", "closed-loop-eq27", "distributed",
                        "centralized", "average", "best-single"}) {
    EXPECT_EQ(run("heading --in " + path("H.csv") + " --out " + path("F.csv") + " --method " + m),
              0)
        << m << ": " << read("err.txt");
  }
  EXPECT_EQ(run("heading --in " + path("H.csv") + " --out " + path("F.csv") + " --method kalman"),
            2);
  EXPECT_NE(read("err.txt").find("closed-loop"), std::string::npos);  // lists the known ones
  EXPECT_EQ(
      run("heading --in " + path("H.csv") + " --out " + path("F.csv") + " --noise-deg 0.1,0.2,0.3"),
      2);
  EXPECT_EQ(run("heading-sim no-such-scenario --out " + path("X.csv")), 2);
}

TEST_F(HeadingCli, BadFilesGiveOneLineAndStatusTwo) {
  const struct {
    const char* name;
    const char* text;
    const char* where;
  } cases[] = {
      {"gap.csv", "t_s,h1_deg,h3_deg\n0,1,2\n", "gap.csv:1:"},
      {"text.csv", "t_s,h1_deg\n0,1\n0.1,abc\n", "text.csv:3:"},
      {"unsorted.csv", "t_s,h1_deg\n0.2,1\n0.1,1\n", "unsorted.csv:3:"},
      {"empty.csv", "", "empty.csv"},
      {"notime.csv", "h1_deg\n1\n", "notime.csv"},
      {"nosensor.csv", "t_s,x\n0,1\n", "nosensor.csv"},
  };
  for (const auto& c : cases) {
    write(c.name, c.text);
    EXPECT_EQ(run("heading --in " + path(c.name) + " --out " + path("F.csv")), 2) << c.name;
    const std::string err = read("err.txt");
    EXPECT_NE(err.find(c.where), std::string::npos) << c.name << ": " << err;
    EXPECT_EQ(err.find('\n'), err.size() - 1) << c.name << ": one line, got " << err;
  }
  EXPECT_EQ(run("heading --in " + path("missing.csv") + " --out " + path("F.csv")), 2);
}

TEST_F(HeadingCli, EvalPrintsATableRow) {
  ASSERT_EQ(run("heading-eval --scenario paper-small --method closed-loop,distributed --seeds 2"),
            0)
      << read("err.txt");
  const std::string out = read("out.txt");
  EXPECT_NE(out.find("| paper-small | closed-loop |"), std::string::npos) << out;
  EXPECT_NE(out.find("| paper-small | distributed |"), std::string::npos) << out;
}

}  // namespace
