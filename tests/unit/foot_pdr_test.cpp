// FootPdr (seed 004): a foot-mounted IMU's dead reckoning on the gait simulator's foot walks.
#include "telltale/fusion/foot_pdr.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::fusion {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Given a foot sensor on straight walks of five simulated people, when FootPdr runs with each
// walker's height, then it counts every step (one event per stride, two steps each), the
// distance is the step-length model's and the track points the way the walk went, give or take
// some degrees; the output has no pose.
TEST(FootPdr, CountsTwoStepsPerStrideAndLaysTheWalk) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto run = sim::simulate_gait(*sim::make_gait_scenario("foot-walk", seed),
                                        sim::random_person(seed), seed);
    FootPdrParams p;
    p.step_length.height_m = sim::random_person(seed).height_m;
    FootPdr pdr(p);
    std::size_t strides = 0;
    for (const auto& s : run.samples) strides += pdr.update(s.imu, s.mag_uT).step ? 1u : 0u;
    const auto& out = pdr.output();
    const auto& last = run.samples.back();
    EXPECT_EQ(out.steps, 2 * strides) << seed;
    EXPECT_NEAR(static_cast<double>(out.steps), static_cast<double>(run.step_times_s.size()), 2.0)
        << seed;
    // As measured when FootPdr left Pdr (seeds 1-5): distance within 17 %, the track's
    // bearing 6-11 deg off the walk's.
    EXPECT_NEAR(out.distance_m, run.distance_m, 0.2 * run.distance_m) << seed;
    const double off_deg =
        std::remainder(std::atan2(out.x_m, out.y_m) - std::atan2(last.x_m, last.y_m), 2 * M_PI) /
        kDeg;
    EXPECT_LT(std::abs(off_deg), 15.0) << seed;
    EXPECT_EQ(out.pose, PhonePose::kHandHeld);
    EXPECT_FALSE(out.switching);
    EXPECT_GT(out.cadence_spm, 80.0) << seed;
  }
}

}  // namespace
}  // namespace telltale::fusion
