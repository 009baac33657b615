// Change indication (PX4 EKF2's idea): the production filter's output on a fixed short input is
// committed as tests/data/attitude_golden_telltale.csv, and any numerical change shows here as a
// list of the rows that moved by more than 1e-6 deg, not only as a threshold crossed elsewhere.
//
// Input: the simulator's pendulum-heel-20, seed 2, 25 Hz, 20 s (5 s held, then swinging: the
// rest, the bias learning and the motion all run), every 2nd sample written.
//
// When a change is intended, regenerate and commit the file with the change:
//   TELLTALE_UPDATE_GOLDEN=1 build/bin/fusion_core_tests --gtest_filter='AttitudeGolden.*'
// (it writes the file in the source tree and fails once, saying so).
// Seen failing: run against the filter before the VQF-style rebuild, every row after the first differs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::fusion {
namespace {

struct Row {
  double t_s, heel_deg, pitch_deg;
};

std::vector<Row> produce() {
  auto sc = sim::make_scenario("pendulum-heel-20", 2, 25.0, 20.0);
  TelltaleAttitudeFilter f;
  ImuSample s;
  sim::AttitudeTruth truth;
  std::vector<Row> rows;
  int k = 0;
  while (sc->next(s, truth)) {
    f.update(s);
    if (k++ % 2 != 0) continue;
    const AttitudeOutput o = f.output();
    rows.push_back({s.t_s, o.heel_rad * 180.0 / M_PI, o.pitch_rad * 180.0 / M_PI});
  }
  return rows;
}

TEST(AttitudeGolden, ProductionFilterOutputUnchanged) {
  const std::string path = std::string(TELLTALE_TEST_DATA_DIR) + "/attitude_golden_telltale.csv";
  const std::vector<Row> now = produce();
  if (std::getenv("TELLTALE_UPDATE_GOLDEN") != nullptr) {
    std::ofstream os(path);
    os << "t_s,heel_deg,pitch_deg\n";
    char line[128];
    for (const Row& r : now) {
      std::snprintf(line, sizeof line, "%.4f,%.9f,%.9f\n", r.t_s, r.heel_deg, r.pitch_deg);
      os << line;
    }
    FAIL() << "wrote " << now.size() << " rows to " << path << ": review and commit it";
  }
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << "missing " << path << " (see the header of this test)";
  std::string line;
  std::getline(in, line);
  std::vector<Row> golden;
  while (std::getline(in, line)) {
    Row r{};
    char c1 = 0, c2 = 0;
    std::istringstream ss(line);
    ss >> r.t_s >> c1 >> r.heel_deg >> c2 >> r.pitch_deg;
    golden.push_back(r);
  }
  ASSERT_EQ(golden.size(), now.size());
  constexpr double kTolDeg = 1e-6;
  int differing = 0;
  std::string report;
  for (std::size_t i = 0; i < now.size(); ++i) {
    const double dh = now[i].heel_deg - golden[i].heel_deg;
    const double dp = now[i].pitch_deg - golden[i].pitch_deg;
    if (std::abs(dh) <= kTolDeg && std::abs(dp) <= kTolDeg) continue;
    if (++differing <= 20) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "  t=%.2f heel %.6f -> %.6f (%+.2e)  pitch %.6f -> %.6f (%+.2e)\n",
                    golden[i].t_s, golden[i].heel_deg, now[i].heel_deg, dh, golden[i].pitch_deg,
                    now[i].pitch_deg, dp);
      report += buf;
    }
  }
  EXPECT_EQ(differing, 0) << differing << " of " << now.size()
                          << " rows differ by more than 1e-6 deg (first 20):\n"
                          << report;
}

}  // namespace
}  // namespace telltale::fusion
