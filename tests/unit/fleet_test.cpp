// The fleet model's judgement of a boat, and the problems the dashboard shows on its card.
#include <gtest/gtest.h>

#include "fleet.hpp"
#include "json_views.hpp"
#include "telltale.h"

namespace telltale::shore {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

AttitudeSample sample(std::uint64_t boot, std::uint64_t seq) {
  AttitudeSample s;
  s.boat_id = "b1";
  s.boot_id = boot;
  s.seq = seq;
  s.t_utc_ns = 1795300000ULL * 1000000000ULL + seq * 40'000'000ULL;
  return s;
}

/// One sample of run `boot`, arriving at `t` with the boat's clock right.
void feed(FleetModel& fleet, std::uint64_t boot, std::uint64_t seq, SteadyTime t) {
  const AttitudeSample s = sample(boot, seq);
  fleet.update(s, t, s.t_utc_ns);
}

std::vector<std::string> codes(const BoatView& v) {
  std::vector<std::string> out;
  for (const auto& p : boat_problems(v)) out.push_back(p.at("code").get<std::string>());
  return out;
}

// Given a boat node restarted (run 1 stops, run 2 starts a second later), the model does not
// call it two nodes: a restart switches run once and never back.
TEST(FleetDuplicates, ARestartIsNotTwoNodes) {
  FleetModel fleet(milliseconds(2000));
  const SteadyTime t0 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 1; i <= 50; ++i) feed(fleet, 1, i, t0 + i * milliseconds(40));
  for (std::uint64_t i = 1; i <= 50; ++i)
    feed(fleet, 2, i, t0 + seconds(3) + i * milliseconds(40));
  const auto v = fleet.boat("b1");
  ASSERT_TRUE(v);
  EXPECT_FALSE(v->duplicate_id);
  EXPECT_TRUE(codes(*v).empty());
}

// Given two nodes configured with one id, both at 25 Hz, the model flags the boat within the
// first switch back, names both runs, and clears the flag 10 s after one node stops.
TEST(FleetDuplicates, TwoNodesUnderOneIdAreFlaggedAndClearedWhenOneStops) {
  FleetModel fleet(milliseconds(2000));
  const SteadyTime t0 = std::chrono::steady_clock::now();
  SteadyTime t = t0;
  for (std::uint64_t i = 1; i <= 50; ++i) {
    t = t0 + i * milliseconds(40);
    feed(fleet, 7, i, t);
    feed(fleet, 9, i, t + milliseconds(5));
  }
  auto v = fleet.boat("b1");
  ASSERT_TRUE(v);
  EXPECT_TRUE(v->duplicate_id);
  const auto problems = boat_problems(*v);
  ASSERT_EQ(codes(*v), std::vector<std::string>{"duplicate_id"});
  const auto text = problems[0].at("text").get<std::string>();
  EXPECT_NE(text.find('7'), std::string::npos) << text;
  EXPECT_NE(text.find('9'), std::string::npos) << text;
  EXPECT_EQ(nlohmann::json::parse(boat_json(*v)).at("duplicate_id"), true);
  // Node 9 stops; node 7 sails on alone.
  for (std::uint64_t i = 51; i <= 400; ++i) feed(fleet, 7, i, t0 + i * milliseconds(40));
  v = fleet.boat("b1");
  EXPECT_FALSE(v->duplicate_id) << "still flagged 14 s after the second node stopped";
}

// Given the boat's status carries the session-log bit and its clock is 2 h off, the card's
// problems say so, the log first; a boat with clean flags has none.
TEST(BoatProblems, LogFailingClockAndSensorFlagsAreNamed) {
  BoatView v;
  v.last = sample(1, 1);
  v.clock_offset_ms = 7.2e6;
  NodeStatusInfo st;
  st.sensor_health = msg::SENSOR_LOG_FAILING | msg::SENSOR_SATURATED;
  st.health_text = "SESSION LOG FAILING (No space left on device): 12 held in memory";
  v.status = st;
  const auto p = boat_problems(v);
  ASSERT_EQ(codes(v), (std::vector<std::string>{"log_failing", "clock_suspect", "sensor"}));
  EXPECT_EQ(p[0].at("text"), st.health_text);
  EXPECT_NE(p[1].at("text").get<std::string>().find("+7200.0 s"), std::string::npos) << p[1];
  EXPECT_EQ(p[2].at("text"), "IMU saturated");
  v.clock_offset_ms = 3.0;
  v.status->sensor_health = 0;
  EXPECT_TRUE(boat_problems(v).empty());
}

}  // namespace
}  // namespace telltale::shore
