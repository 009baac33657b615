// Gait simulator: physical invariants and the bookkeeping of its truth.
#include "telltale/fusion/sim/gait_sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace telltale::fusion::sim {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;

TEST(GaitSim, PeopleSpanTheHeightRangeAndGaitsOrderByCadenceAndLength) {
  double lo = 9, hi = 0;
  for (std::uint64_t s = 1; s <= 200; ++s) {
    const Person p = random_person(s);
    lo = std::min(lo, p.height_m);
    hi = std::max(hi, p.height_m);
    for (int g = 1; g < kGaitCount; ++g) {
      EXPECT_GT(nominal_step_hz(static_cast<Gait>(g), p),
                nominal_step_hz(static_cast<Gait>(g - 1), p));
      EXPECT_GT(nominal_step_length_m(static_cast<Gait>(g), p),
                nominal_step_length_m(static_cast<Gait>(g - 1), p));
    }
  }
  EXPECT_GE(lo, 1.55);
  EXPECT_LE(hi, 1.95);
  EXPECT_LT(lo, 1.60);
  EXPECT_GT(hi, 1.90);
}

TEST(GaitSim, DeterministicForASeed) {
  const auto sc = *make_gait_scenario("phone-arm-swing-walk", 3);
  const auto a = simulate_gait(sc, random_person(3), 3);
  const auto b = simulate_gait(sc, random_person(3), 3);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); i += 97)
    EXPECT_EQ(a.samples[i].imu.acc_body_m_s2, b.samples[i].imu.acc_body_m_s2);
}

// Standing still: specific force g, no rotation, field magnitude of the earth's.
TEST(GaitSim, AtRestTheSensorsSeeGravityAndTheEarthField) {
  for (const char* name : {"foot-walk", "phone-call-walk", "phone-pocket-walk"}) {
    const auto run = simulate_gait(*make_gait_scenario(name, 2), random_person(2), 2);
    for (const auto& s : run.samples) {
      if (s.imu.t_s > 1.5) break;
      EXPECT_NEAR(s.imu.acc_body_m_s2.norm(), kG, 0.3) << name;
      EXPECT_LT(s.imu.gyro_body_rad_s.norm(), 0.1) << name;
      EXPECT_NEAR(s.mag_uT.norm(), std::hypot(20.0, 44.0), 4.0) << name;
    }
  }
}

// The phone's orientation is continuous when the walk starts and stops: its gyro never reads
// more than the trunk and hand can turn it (a jump of the trunk sway at the first step once read
// 11-22 rad/s for one sample, 13 deg of rotation that never happened).
TEST(GaitSim, PhoneRateStaysPhysicalWhenTheWalkStartsAndStops) {
  for (const char* name : {"phone-hand-held-walk", "phone-call-walk", "phone-pocket-walk"}) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const auto sc = make_gait_scenario(name, seed);
      const auto run = simulate_gait(*sc, random_person(seed), seed);
      const double t_start = sc->standing_s;  // the walk starts (its first heel strike is later)
      const double t_stop = run.samples.back().imu.t_s - 2.0;  // standing 2 s after the walk
      double worst = 0.0;
      for (const auto& s : run.samples)
        if (std::abs(s.imu.t_s - t_start) < 0.5 || std::abs(s.imu.t_s - t_stop) < 0.5)
          worst = std::max(worst, s.imu.gyro_body_rad_s.norm());
      EXPECT_LT(worst, 2.0) << name << " seed " << seed;
    }
  }
}

// The foot's closing heel strike slaps it flat as every heel strike does: around it the gyro
// reads no more than the swings before it turned the foot (the foot once snapped flat in one
// sample there, 35 rad/s for 4 ms, 20 deg of rotation that never happened).
TEST(GaitSim, FootRateStaysPhysicalWhenTheWalkStops) {
  for (const char* name : {"foot-slow-walk", "foot-walk", "foot-run"}) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const auto run = simulate_gait(*make_gait_scenario(name, seed), random_person(seed), seed);
      const double t_close = run.foot_step_times_s.back();
      double walk = 0.0, closing = 0.0;
      for (const auto& s : run.samples) {
        const double w = s.imu.gyro_body_rad_s.norm();
        if (s.imu.t_s < t_close - 0.5) walk = std::max(walk, w);
        if (std::abs(s.imu.t_s - t_close) < 0.2) closing = std::max(closing, w);
      }
      EXPECT_LT(closing, walk) << name << " seed " << seed;
    }
  }
}

// Walking: the truth counts, distance and foot/body relation add up, and the mean vertical
// specific force over the walk is g (no net vertical acceleration).
TEST(GaitSim, TruthBookkeepingAddsUp) {
  for (const char* name : {"foot-mixed", "body-run", "phone-switch"}) {
    const auto run = simulate_gait(*make_gait_scenario(name, 7), random_person(7), 7);
    EXPECT_EQ(run.foot_step_times_s.size() * 2, run.step_times_s.size()) << name;
    EXPECT_EQ(static_cast<std::size_t>(run.samples.back().steps), run.step_times_s.size());
    EXPECT_EQ(static_cast<std::size_t>(run.samples.back().foot_steps),
              run.foot_step_times_s.size());
    EXPECT_NEAR(run.samples.back().distance_m, run.distance_m, 1e-9);
    double mean_mag = 0;
    for (const auto& s : run.samples) mean_mag += s.imu.acc_body_m_s2.norm();
    mean_mag /= static_cast<double>(run.samples.size());
    EXPECT_GT(mean_mag, kG - 0.2) << name;
  }
}

// A walk starts and ends as a real one does (the IPOL lower-back trials): at its start no heel
// strike loads the trunk, only the push of the first toe-off lifts it, by a quarter of a
// loading (the truth's first heel strike is a step later); it ends at the closing heel strike,
// whose loading brings the trunk to rest, in a walk and a run alike (a run cannot stop in
// mid-flight). Measured on the trunk's specific force |f| - g, at 100 Hz, without sensor noise.
TEST(GaitSim, AWalkStartsWithAPushAndEndsAtAClosingHeelStrike) {
  for (const char* gait : {"slow-walk", "walk", "fast-walk", "jog", "run"}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      auto sc = make_gait_scenario(std::string("body-") + gait, seed);
      ASSERT_TRUE(sc);
      sc->errors = {.acc_noise_m_s2 = 0.0,
                    .acc_bias_m_s2 = 0.0,
                    .gyro_noise_rad_s = 0.0,
                    .gyro_bias_rad_s = 0.0,
                    .mag_noise_uT = 0.0,
                    .mag_bias_uT = 0.0};
      const auto run = simulate_gait(*sc, random_person(seed), seed);
      const double start = sc->standing_s, first_hs = run.step_times_s.front();
      const double closing = run.step_times_s.back();
      const double step = first_hs - start;  // step 0's period
      EXPECT_GT(step, 0.25) << gait << " seed " << seed;
      double push = 0, walk = 0, after_closing = 0, standing = 0;
      for (const auto& s : run.samples) {
        const double t = s.imu.t_s, f = s.imu.acc_body_m_s2.norm() - kG;
        if (t >= start && t < start + 0.25 * step) push = std::max(push, f);
        if (t > first_hs + 2.0 && t < closing - 2.0) walk = std::max(walk, f);
        if (t >= closing && t < closing + 0.15) after_closing = std::max(after_closing, f);
        if (t > closing + 0.5) standing = std::max(standing, std::abs(f));
      }
      EXPECT_LT(push, 0.4 * walk) << gait << " seed " << seed;
      EXPECT_GT(after_closing, 0.5 * walk) << gait << " seed " << seed;
      EXPECT_LT(standing, 0.05) << gait << " seed " << seed;
    }
  }
}

// A closed loop returns to its start within two steps (the walk ends on the step that completes
// the path, with an even number of steps so both feet stand together).
TEST(GaitSim, ClosedLoopReturnsToTheStart) {
  for (std::uint64_t s = 1; s <= 5; ++s) {
    const auto run = simulate_gait(*make_gait_scenario("loop", s), random_person(s), s);
    const auto& last = run.samples.back();
    EXPECT_LT(std::hypot(last.x_m, last.y_m), 1.7);
    EXPECT_GT(run.distance_m, 55.0);
  }
}

// Foot: stance then swing; in swing the foot turns fastest about its pitch axis (y) and, as a real
// foot does, about its long axis and the vertical as well (the IPOL feet: 0.3-1 x the pitch rate
// in the swing); running reaches higher rates and forces than slow walking.
TEST(GaitSim, FootRotatesAboutItsPitchAxisAndRunningIsHarder) {
  auto peak = [](const char* name) {
    const auto run = simulate_gait(*make_gait_scenario(name, 4), random_person(4), 4);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    double f = 0, on = 0, off = 0;
    for (const auto& s : run.samples) {
      const Eigen::Vector3d& g = s.imu.gyro_body_rad_s;
      w = w.cwiseMax(g.cwiseAbs());
      f = std::max(f, s.imu.acc_body_m_s2.norm());
      if (g.norm() > 1.0) {
        on += g.y() * g.y();
        off += g.x() * g.x() + g.z() * g.z();
      }
    }
    return std::make_tuple(w, f, std::sqrt(off / on));
  };
  const auto [slow_w, slow_f, slow_off] = peak("foot-slow-walk");
  const auto [run_w, run_f, run_off] = peak("foot-run");
  EXPECT_GT(slow_w.y(), 2.0 * slow_w.x());
  EXPECT_GT(slow_off, 0.1);
  EXPECT_GT(run_off, 0.1);
  EXPECT_GT(run_w.y(), slow_w.y());
  EXPECT_GT(run_f, slow_f);
}

// Between heel-off and heel strike the foot turns toes-down (heel-off to toe-off), then at once
// back toes-up through the swing: its largest plantar flexion is a turning point the pitch rate
// crosses, not a rest. A simulated foot that rested there (two minimum-jerk moves meeting at
// zero rate and zero angular acceleration) sat under 0.3 rad/s for 0.05-0.06 s mid-stride, and
// the step detectors split its swing in two (docs/steps.md); crossing, it passes 0.3 rad/s either
// side in 0.01-0.02 s. Every walker, every gait, 100 Hz: no more than 3 samples under 0.3 rad/s
// in a row from the first fast turn of the heel-off to the last of the swing.
TEST(GaitSim, TheFootDoesNotRestBetweenToeOffAndTheSwing) {
  for (const char* gait :
       {"foot-slow-walk", "foot-walk", "foot-fast-walk", "foot-jog", "foot-run"}) {
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      const auto run = simulate_gait(*make_gait_scenario(gait, seed), random_person(seed), seed);
      const auto& hs = run.foot_step_times_s;
      ASSERT_GT(hs.size(), 10u);
      int worst = 0;
      for (std::size_t k = 0; k + 1 < hs.size(); ++k) {
        // The stride's second part (after foot flat): heel-off, toe-off, swing.
        const double t0 = hs[k] + 0.3 * (hs[k + 1] - hs[k]), t1 = hs[k + 1] - 0.02;
        std::vector<double> w;
        for (const auto& s : run.samples)
          if (s.imu.t_s > t0 && s.imu.t_s < t1) w.push_back(s.imu.gyro_body_rad_s.norm());
        const auto first = std::find_if(w.begin(), w.end(), [](double x) { return x > 2.0; });
        const auto last = std::find_if(w.rbegin(), w.rend(), [](double x) { return x > 2.0; });
        int run_below = 0;
        for (auto it = first; first != w.end() && it < last.base(); ++it) {
          run_below = *it < 0.3 ? run_below + 1 : 0;
          worst = std::max(worst, run_below);
        }
      }
      EXPECT_LE(worst, 3) << gait << " walker " << seed;
    }
  }
}

TEST(GaitSim, UnknownScenariosAreRefused) {
  EXPECT_FALSE(make_gait_scenario("foot-crawl", 1));
  EXPECT_FALSE(make_gait_scenario("phone-bag-walk", 1));
  EXPECT_FALSE(make_gait_scenario("boat", 1));
  for (const auto& e : gait_scenario_examples()) EXPECT_TRUE(make_gait_scenario(e, 1)) << e;
}

}  // namespace
}  // namespace telltale::fusion::sim
