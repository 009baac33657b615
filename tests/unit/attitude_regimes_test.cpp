// Issue 18's regimes for the production filter, on the simulator: a steady turn with the
// instrument tilted on the axis, the paper's turntable and pendulum, a node started under way.
// Given/When/Then through the public API (evaluate_on_scenario scores every sample after the
// scenario's warm-up). Seen failing: against the filter before issue 18 the under-way RMS test
// fails (61 deg RMS: it learns the turning gyro as bias), and the steady-yaw test fails (max
// 14-33 deg) when the yaw scenarios start spinning at power-on instead of after 5 s still; with
// the 5 s rest first the old filter passes the steady-yaw and pendulum tests too (it learns the
// bias at rest). The new filter started spinning with an unknown bias also exceeds 1 deg
// (max 2-8 deg): not covered here yet (issue 18, open).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "telltale/fusion/attitude_eval.hpp"

namespace telltale::fusion {
namespace {

TiltErrorStats run(const std::string& scenario, double rate_hz, int seeds) {
  TiltErrorStats total;
  for (int seed = 1; seed <= seeds; ++seed) {
    total.merge(
        evaluate_on_scenario({"telltale"}, scenario, static_cast<std::uint64_t>(seed), rate_hz)[0]);
  }
  return total;
}

double max_of(const TiltErrorStats& s) { return std::max(s.heel_max_deg, s.pitch_max_deg); }

class SteadyYaw : public ::testing::TestWithParam<int> {};

// Given the instrument at heel -17.5, pitch 7.5 on a turntable's axis, when it is spun up to a
// steady yaw rate, then heel and pitch stay within 1 deg (the accelerometer reads the true tilt
// all the time: a turn must never look like a tilt, nor be learnt as a gyro bias).
TEST_P(SteadyYaw, MaxErrorWithinOneDegree) {
  for (const double rate_hz : {25.0, 100.0}) {
    const TiltErrorStats s = run("yaw-" + std::to_string(GetParam()), rate_hz, 3);
    ASSERT_GT(s.samples, 0u);
    EXPECT_LE(max_of(s), 1.0) << GetParam() << " deg/s at " << rate_hz << " Hz";
  }
}
INSTANTIATE_TEST_SUITE_P(Rates, SteadyYaw, ::testing::Values(10, 30, 60, 90, 120));

// Given the paper's gravity pendulum released from 5..30 deg, mounted for heel and for pitch,
// sampled at 25 and 100 Hz, then the max error is within the paper's +-1 deg.
TEST(Regimes, PendulumMaxWithinOneDegree) {
  for (const char* mount : {"heel", "pitch"}) {
    for (int a : {5, 10, 15, 20, 25, 30}) {
      for (const double rate_hz : {25.0, 100.0}) {
        const std::string name = std::string("pendulum-") + mount + "-" + std::to_string(a);
        EXPECT_LE(max_of(run(name, rate_hz, 2)), 1.0) << name << " at " << rate_hz << " Hz";
      }
    }
  }
}

// Given the paper's turntable (yaw rate swinging up to +-90 deg/s, off the axis), then the
// output moves less than +-1 deg.
TEST(Regimes, TurntableMaxWithinOneDegree) {
  EXPECT_LE(max_of(run("turntable", 25.0, 3)), 1.0);
  EXPECT_LE(max_of(run("turntable", 100.0, 3)), 1.0);
}

// Given a node started while sailing (bow-mounted, waves, gyro bias up to 10 deg/s unknown, no
// rest), then after 15 s its RMS error is below every baseline's (each >= 2.2 deg).
TEST(Regimes, StartedUnderWayBeatsTheBaselines) {
  const TiltErrorStats s = run("underway-15", 25.0, 3);
  EXPECT_LE(s.heel_rms_deg, 2.0);
  EXPECT_LE(s.pitch_rms_deg, 2.0);
}

// Given the same start under way, then the worst error after 5 s and after 15 s stays at what the
// filter measures today (10.3 and 8.4 deg, 3 seeds): a regression shows. The goal is 2 and 1 deg;
// what stands in the way is the gyro bias (up to 10 deg/s, unknown at the start) learnt
// overconfidently in motion, and the tacks' centripetal acceleration.
TEST(Regimes, StartedUnderWayWorstErrorDoesNotGrow) {
  EXPECT_LE(max_of(run("underway-5", 25.0, 3)), 11.0);
  EXPECT_LE(max_of(run("underway-15", 25.0, 3)), 9.0);
}

}  // namespace
}  // namespace telltale::fusion
