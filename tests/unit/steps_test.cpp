// Step detectors: analytic invariants of the building blocks, accuracy against the gait
// simulator's truth over 10 people per gait (TEST_P), the baselines beside them, accelerometer-only
// input, bad samples, and the real Oxford phone traces in tests/data/oxford_steps.
#include "telltale/fusion/steps.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "oxford_traces.hpp"
#include "telltale/fusion/gait_phase_steps.hpp"
#include "telltale/fusion/peak_valley_steps.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::fusion {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;

double accuracy(std::size_t counted, std::size_t truth) {
  return 1.0 - std::abs(static_cast<double>(counted) - static_cast<double>(truth)) /
                   static_cast<double>(truth);
}

std::size_t count(StepDetector& d, const std::vector<sim::GaitSample>& samples,
                  bool drop_gyro = false) {
  d.reset();
  std::size_t n = 0;
  StepEvent ev;
  for (auto s : samples) {
    if (drop_gyro) s.imu.gyro_body_rad_s.setConstant(std::numeric_limits<double>::quiet_NaN());
    n += d.update(s.imu, ev) ? 1u : 0u;
  }
  while (d.flush(ev)) ++n;
  return n;
}

TEST(SignedMeanWindow, MeansOfPositiveAndNegativeSamplesOverTheWindow) {
  SignedMeanWindow w;
  // 0.5 s of +2, then 0.5 s of -1 and +4 alternating, at 100 Hz; window 0.6 s.
  for (int k = 0; k < 50; ++k) w.push(k * 0.01, 2.0, 0.6);
  EXPECT_DOUBLE_EQ(w.positive_mean(), 2.0);
  EXPECT_DOUBLE_EQ(w.negative_mean(), 0.0);
  for (int k = 50; k < 150; ++k) w.push(k * 0.01, k % 2 ? -1.0 : 4.0, 0.6);
  // Only the last 0.6 s remain: 61 samples alternating.
  EXPECT_NEAR(w.positive_mean(), 4.0, 1e-12);
  EXPECT_NEAR(w.negative_mean(), -1.0, 1e-12);
  EXPECT_EQ(w.size(), 61u);
}

TEST(SignedMeanWindow, FullBufferDropsTheOldest) {
  SignedMeanWindow w;
  for (std::size_t k = 0; k < 3 * SignedMeanWindow::kCapacity; ++k)
    w.push(static_cast<double>(k) * 1e-4, static_cast<double>(k % 3) - 1.0, 100.0);
  EXPECT_EQ(w.size(), SignedMeanWindow::kCapacity);
  EXPECT_NEAR(w.positive_mean(), 1.0, 1e-12);
  EXPECT_NEAR(w.negative_mean(), -1.0, 1e-12);
}

TEST(LowPass2, UnitDcGainAndMonotoneStepResponseAtAnyRate) {
  for (double dt : {0.0025, 0.01, 0.02, 0.04}) {
    LowPass2 lp(3.0);
    double prev = lp.step(0.0, dt);
    for (int k = 0; k < static_cast<int>(3.0 / dt); ++k) {
      const double y = lp.step(1.0, dt);
      EXPECT_GE(y, prev - 1e-15);
      prev = y;
    }
    EXPECT_NEAR(prev, 1.0, 1e-6);
  }
}

TEST(StepRegistry, EveryNameBuildsForEveryMountAndUnknownIsNull) {
  for (auto name : step_detector_names())
    for (auto mount : {StepMount::kFoot, StepMount::kBody}) {
      auto d = make_step_detector(name, mount);
      ASSERT_NE(d, nullptr);
      EXPECT_EQ(d->name(), name);
    }
  EXPECT_EQ(make_step_detector("nope", StepMount::kFoot), nullptr);
  EXPECT_EQ(default_step_detector(StepMount::kFoot), "gait-phase");
  EXPECT_EQ(default_step_detector(StepMount::kBody), "peak-valley");
}

// Given a sensor lying still, when samples (some with NaN, some with time going back) arrive,
// then no step is counted and the rejects are counted.
TEST(StepDetectors, StillSensorCountsNothingAndRejectsBadSamples) {
  for (auto name : step_detector_names()) {
    auto d = make_step_detector(name, StepMount::kBody);
    StepEvent ev;
    int steps = 0;
    for (int k = 0; k < 2000; ++k) {
      ImuSample s{k * 0.01, {0.001 * std::sin(k), 0, 0}, {0.02 * std::sin(0.7 * k), 0, kG}};
      steps += d->update(s, ev);
    }
    d->update({std::nan(""), {0, 0, 0}, {0, 0, kG}}, ev);
    d->update({30.0, {0, 0, 0}, {std::nan(""), 0, kG}}, ev);
    d->update({5.0, {0, 0, 0}, {0, 0, kG}}, ev);
    EXPECT_EQ(steps, 0) << name;
    EXPECT_EQ(d->diagnostics().rejected_non_finite, 2u) << name;
    EXPECT_EQ(d->diagnostics().rejected_time, 1u) << name;
  }
}

// --- accuracy on the simulator, every gait x 10 people ------------------------------------------
struct GaitCase {
  std::string site;  // foot | body
  std::string gait;  // slow-walk ... run | mixed
};
void PrintTo(const GaitCase& c, std::ostream* os) { *os << c.site << "-" << c.gait; }
std::string case_name(const testing::TestParamInfo<GaitCase>& info) {
  std::string n = info.param.site + "_" + info.param.gait;
  for (auto& c : n)
    if (c == '-') c = '_';
  return n;
}

class GaitAccuracy : public testing::TestWithParam<GaitCase> {};

// Given 10 simulated people (1.55-1.95 m, own cadence and step length) in one gait, when each
// detector counts, then the default detector of the mount (`fusion_cli steps --mount foot|body`:
// gait-phase on both) is >= 99 % accurate for every person's mean (>= 97 % for the worst person)
// and never worse than the peak and fixed-threshold baselines, and every detector's figure is
// reported beside it. Seed 004 claims 98 % for its adaptive detector: asserted too (on the
// trunk it misses the first step after standing, as on the IPOL lower-back trials, and stays
// above 98 % only because the simulated walks are long).
TEST_P(GaitAccuracy, DefaultDetectorAtLeast99PercentAndBaselinesBeside) {
  const auto& c = GetParam();
  const auto mount = c.site == "foot" ? StepMount::kFoot : StepMount::kBody;
  const std::string lead = "gait-phase";
  std::map<std::string, double> mean;
  double worst_lead = 1.0;
  for (int p = 1; p <= 10; ++p) {
    const auto seed = static_cast<std::uint64_t>(p);
    const auto sc = sim::make_gait_scenario(c.site + "-" + c.gait, seed);
    ASSERT_TRUE(sc);
    const auto run = sim::simulate_gait(*sc, sim::random_person(seed), seed);
    const std::size_t truth =
        mount == StepMount::kFoot ? run.foot_step_times_s.size() : run.step_times_s.size();
    ASSERT_GT(truth, 20u);
    for (auto name : step_detector_names()) {
      auto d = make_step_detector(name, mount);
      const double acc = accuracy(count(*d, run.samples), truth);
      mean[std::string(name)] += acc / 10.0;
      if (name == lead) worst_lead = std::min(worst_lead, acc);
    }
  }
  for (const auto& [name, acc] : mean) RecordProperty(name, std::to_string(100.0 * acc));
  EXPECT_GE(mean[lead], 0.99);
  EXPECT_GE(worst_lead, 0.97);
  EXPECT_GE(mean[lead] + 1e-12, mean["peak"]);
  EXPECT_GE(mean[lead] + 1e-12, mean["fixed-threshold"]);
  EXPECT_GE(mean["adaptive"], 0.98);
}

INSTANTIATE_TEST_SUITE_P(EveryGait, GaitAccuracy,
                         testing::Values(GaitCase{"foot", "slow-walk"}, GaitCase{"foot", "walk"},
                                         GaitCase{"foot", "fast-walk"}, GaitCase{"foot", "jog"},
                                         GaitCase{"foot", "run"}, GaitCase{"foot", "mixed"},
                                         GaitCase{"body", "slow-walk"}, GaitCase{"body", "walk"},
                                         GaitCase{"body", "fast-walk"}, GaitCase{"body", "jog"},
                                         GaitCase{"body", "run"}, GaitCase{"body", "mixed"}),
                         case_name);

// The paper's claim about the baselines, as far as it holds here: fixed thresholds tuned for a
// normal walk miss a body-worn slow walk entirely and lose steps when gaits change.
TEST(Baselines, FailOnNonNormalGaitsOfABodyWornSensor) {
  for (const char* gait : {"slow-walk", "mixed"}) {
    const auto sc = sim::make_gait_scenario(std::string("body-") + gait, 3);
    const auto run = sim::simulate_gait(*sc, sim::random_person(3), 3);
    for (const char* name : {"peak", "fixed-threshold"}) {
      auto d = make_step_detector(name, StepMount::kBody);
      EXPECT_LT(accuracy(count(*d, run.samples), run.step_times_s.size()), 0.95) << gait << name;
    }
  }
}

// Accelerometer-only input (no gyro columns): the foot detector keeps its acceleration and time
// conditions and stays >= 99 % on a mixed-gait walk.
TEST(AdaptiveStepDetector, AccelerometerOnlyFootStillCounts) {
  for (int p = 1; p <= 3; ++p) {
    const auto seed = static_cast<std::uint64_t>(p);
    const auto run = sim::simulate_gait(*sim::make_gait_scenario("foot-mixed", seed),
                                        sim::random_person(seed), seed);
    AdaptiveStepDetector d;
    EXPECT_GE(accuracy(count(d, run.samples, true), run.foot_step_times_s.size()), 0.99);
    EXPECT_FALSE(d.diagnostics().gyro_used);
  }
}

// Seed 003: step detection close to 100 % in single poses (phone, walking). In arm swing the
// hand's pendulum (10-25 m/s^2) swamps the trunk's acceleration: there the arm's turns count
// (SwingStepDetector, next test) and the peak-valley detector's figure is only reported.
TEST(PeakValleyStepDetector, PhoneInEveryPoseWalking) {
  for (const char* pose : {"hand-held", "call", "pocket", "arm-swing"}) {
    double mean = 0;
    for (int p = 1; p <= 5; ++p) {
      const auto seed = static_cast<std::uint64_t>(p);
      const auto sc = sim::make_gait_scenario(std::string("phone-") + pose + "-walk", seed);
      const auto run = sim::simulate_gait(*sc, sim::random_person(seed), seed);
      PeakValleyStepDetector d;
      mean += accuracy(count(d, run.samples, true), run.step_times_s.size()) / 5.0;
    }
    RecordProperty(std::string(pose) + "_mean_accuracy", std::to_string(mean));
    if (std::string(pose) != "arm-swing") {
      EXPECT_GE(mean, 0.99) << pose;
    }
  }
}

// --- a phone handled, not carried ---------------------------------------------------------------
TEST(TiltWindow, AngleBetweenTheLastSecondAndTheOneBeforeAtAnyRate) {
  const Eigen::Vector3d down(0.0, 0.0, kG);
  const Eigen::Vector3d tilted =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * down;
  for (double rate : {50.0, 100.0, 400.0}) {
    TiltWindow w;
    EXPECT_EQ(w.angle_rad(), 0.0);
    const auto n = static_cast<int>(std::lround(4.0 * rate));
    double at_one_s = -1.0, at_two_s = -1.0, at_three_s = -1.0;
    for (int k = 0; k <= n; ++k) {
      const double t = k / rate;
      w.add(t, t < 2.0 ? down : tilted);  // tilted by 40 deg at t = 2 s
      if (k == static_cast<int>(rate)) at_one_s = w.angle_rad();
      if (k == static_cast<int>(2.0 * rate) - 1) at_two_s = w.angle_rad();
      if (k == static_cast<int>(3.0 * rate)) at_three_s = w.angle_rad();
    }
    // Held still: the halves agree (to acos's resolution near 1, ~1e-8 rad).
    EXPECT_NEAR(at_one_s, 0.0, 1e-7) << rate;
    EXPECT_NEAR(at_two_s, 0.0, 1e-7) << rate;
    // At 3 s the last whole second is tilted, the one before is not.
    EXPECT_NEAR(at_three_s * 180.0 / M_PI, 40.0, 1e-9) << rate;
    EXPECT_NEAR(w.angle_rad(), 0.0, 1e-7) << rate;  // two seconds after: still again
  }
}

TEST(TiltWindow, AGapLongerThanTheWindowStartsItAgain) {
  TiltWindow w;
  for (int k = 0; k < 200; ++k) w.add(k * 0.01, Eigen::Vector3d(0.0, 0.0, kG));
  w.add(10.0, Eigen::Vector3d(kG, 0.0, 0.0));  // 8 s later, on its side
  EXPECT_EQ(w.angle_rad(), 0.0);               // nothing before the gap is compared with it
  for (int k = 1; k < 100; ++k) w.add(10.0 + k * 0.01, Eigen::Vector3d(kG, 0.0, 0.0));
  EXPECT_NEAR(w.angle_rad(), 0.0, 1e-7);
}

// A phone taken out of a pocket and turned up to be read while its owner stands: the hand's
// shake (2 Hz, 3 m/s^2 on |f|) passes every amplitude and timing test of a step, but the phone
// tilts through 120 deg in 3 s (40 deg/s), then is held. Six steps with the rule off (so the
// test can fail); none with it.
std::vector<ImuSample> handled_phone(double rate_hz) {
  std::vector<ImuSample> v;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < static_cast<int>(6.0 * rate_hz); ++k) {
    const double t = k / rate_hz;
    const double in_hand = std::clamp(t - 1.5, 0.0, 3.0);  // 1.5-4.5 s
    const double tilt = (120.0 * M_PI / 180.0) * in_hand / 3.0;
    const double shake =
        in_hand > 0.0 && in_hand < 3.0 ? 3.0 * std::sin(2.0 * M_PI * 2.0 * t) : 0.0;
    const Eigen::Vector3d f =
        (kG + shake) * (Eigen::AngleAxisd(tilt, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()) *
                        Eigen::Vector3d::UnitZ());
    v.push_back({t, {nan, nan, nan}, f});
  }
  return v;
}

TEST(PeakValleyStepDetector, APhoneHandledWhileStandingCountsNoStep) {
  for (double rate : {50.0, 100.0, 200.0}) {
    const auto samples = handled_phone(rate);
    for (double max_tilt : {0.0, PeakValleyStepParams{}.max_tilt_deg}) {
      PeakValleyStepParams p;
      p.max_tilt_deg = max_tilt;
      PeakValleyStepDetector d(p);
      StepEvent ev;
      std::size_t n = 0;
      for (const auto& s : samples) n += d.update(s, ev) ? 1u : 0u;
      while (d.flush(ev)) ++n;
      if (max_tilt == 0.0) {
        EXPECT_EQ(n, 6u) << rate;  // every shake passes for a step without the rule
      } else {
        // Each step is judged on the tilt across it (the second after it against the second
        // before), so the handling's first second is seen too.
        EXPECT_EQ(n, 0u) << rate;
        EXPECT_EQ(d.diagnostics().rejected_handling, 6u) << rate;
      }
    }
  }
}

// Held a second, each step is reported with the time it was confirmed, as without the rule; the
// steps still held when the stream ends come out of flush(). A walk that stops with the
// recording: without the flush its last second's steps would be lost.
TEST(PeakValleyStepDetector, HeldStepsKeepTheirTimesAndTheFlushReleasesTheLast) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<ImuSample> walk;
  for (int k = 0; k < 350; ++k) {  // 7 s at 50 Hz, walking from 1 s to the end
    const double t = k * 0.02;
    const double a = t > 1.0 ? 2.0 * std::sin(2.0 * M_PI * 1.8 * (t - 1.0)) : 0.0;
    walk.push_back({t, {nan, nan, nan}, {0.1, 0.2, kG + a}});
  }
  const auto times = [&walk](PeakValleyStepDetector& d, bool flush, std::size_t& before_flush) {
    std::vector<std::pair<double, double>> v;  // time, interval
    StepEvent ev;
    for (const auto& s : walk)
      if (d.update(s, ev)) v.emplace_back(ev.t_s, ev.interval_s);
    before_flush = v.size();
    while (flush && d.flush(ev)) v.emplace_back(ev.t_s, ev.interval_s);
    return v;
  };
  PeakValleyStepParams off;
  off.max_tilt_deg = 0.0;
  PeakValleyStepDetector now(off), held;
  std::size_t n_now = 0, n_held = 0;
  const auto a = times(now, true, n_now);
  const auto b = times(held, true, n_held);
  ASSERT_GE(a.size(), 9u);  // 6 s at 1.8 steps/s
  EXPECT_EQ(a, b);          // the same steps, times and intervals
  // The flush gave exactly the steps of the last second, which no sample came to release.
  const auto last_second = std::count_if(
      b.begin(), b.end(), [&walk](const auto& e) { return e.first > walk.back().t_s - 1.0; });
  EXPECT_GE(last_second, 1);
  EXPECT_EQ(static_cast<long>(b.size() - n_held), last_second);
}

// A walker moving the phone from the hand to the ear, a pocket and a swinging hand walks on: the
// steps of a steady walk count however the phone tilts (the rhythm exemption). The same count
// as with the rule off within 2 steps of ~280 (four switches, each 1.5 s), five people.
TEST(PeakValleyStepDetector, PoseSwitchesWhileWalkingKeepTheirSteps) {
  for (int p = 1; p <= 5; ++p) {
    const auto seed = static_cast<std::uint64_t>(p);
    const auto run = sim::simulate_gait(*sim::make_gait_scenario("phone-switch", seed),
                                        sim::random_person(seed), seed);
    PeakValleyStepParams off;
    off.max_tilt_deg = 0.0;
    PeakValleyStepDetector with_rule, without_rule(off);
    const auto n_with = count(with_rule, run.samples, true);
    const auto n_without = count(without_rule, run.samples, true);
    EXPECT_LE(n_without - std::min(n_with, n_without), 2u) << seed;
    EXPECT_LE(n_with, n_without) << seed;  // the rule only ever refuses
  }
}

// The swing detector on the gyro's horizontal part (up from the accelerometer's slow mean, as a
// phone without a filter would have it).
std::size_t count_swings(const std::vector<sim::GaitSample>& samples,
                         bool* ever_swinging = nullptr) {
  SwingStepDetector d;
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  bool swinging = false;
  for (const auto& s : samples) {
    up += 0.01 * (s.imu.acc_body_m_s2 - up);
    const Eigen::Vector3d u = up.normalized();
    const Eigen::Vector3d& w = s.imu.gyro_body_rad_s;
    n += d.update(s.imu.t_s, w - w.dot(u) * u) ? 1u : 0u;
    swinging = swinging || d.swinging(s.imu.t_s);
  }
  if (ever_swinging) *ever_swinging = swinging;
  return n;
}

// Every step of an arm-swing walk, at every pace, for 10 people: one turn of the arm per step,
// the last one ending at rest. A hand that holds the phone in front of the face or to the ear
// only wobbles (a few degrees, though at up to ~1 rad/s): never a swing.
TEST(SwingStepDetector, CountsEveryStepOfASwingingArmAndNoWobble) {
  for (int p = 1; p <= 10; ++p) {
    const auto seed = static_cast<std::uint64_t>(p);
    const sim::Person person = sim::random_person(seed);
    for (sim::Gait g : {sim::Gait::kSlowWalk, sim::Gait::kWalk, sim::Gait::kFastWalk}) {
      const auto run = sim::simulate_gait(
          sim::straight_phone_walk(g, sim::PhonePose::kArmSwing, 30.0), person, seed);
      // The turns between steps, and the rest that ends the last one: every step.
      EXPECT_EQ(count_swings(run.samples), run.step_times_s.size())
          << "person " << p << " " << sim::gait_name(g);
    }
    for (const char* pose : {"hand-held", "call"}) {
      const auto run = sim::simulate_gait(
          *sim::make_gait_scenario(std::string("phone-") + pose + "-walk", seed), person, seed);
      bool swinging = true;
      (void)count_swings(run.samples, &swinging);
      EXPECT_FALSE(swinging) << pose << " person " << p;
    }
  }
}

TEST(SwingStepDetector, IgnoresNaNAndTimeThatDoesNotAdvance) {
  SwingStepDetector d;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::size_t n = 0;
  for (int k = 0; k < 1000; ++k) {  // 10 s of a 0.9 Hz swing of +-30 deg, 100 Hz
    const double t = 0.01 * k;
    const double rate = 0.52 * 2.0 * M_PI * 0.9 * std::cos(2.0 * M_PI * 0.9 * t);
    n += d.update(t, Eigen::Vector3d(0.0, rate, 0.0)) ? 1u : 0u;
    EXPECT_FALSE(d.update(t, Eigen::Vector3d(0.0, -rate, 0.0)));  // same time again
    EXPECT_FALSE(d.update(t + 0.005, Eigen::Vector3d(nan, 0.0, 0.0)));
  }
  EXPECT_TRUE(d.swinging(9.99));
  EXPECT_NEAR(static_cast<double>(n), 17.0, 1.0);  // 18 turns, the first half swing from rest
}

// --- a real walk's first and last steps ---------------------------------------------
// Given a person standing still, then walking, then stopping, as on the IPOL recordings: the
// first step from standing is short and slow (the foot turns ~15 deg, not 45), and so is the
// step that closes the walk beside the other foot. When a detector runs on it at 50, 100 and
// 200 Hz, then every step is counted, the small ones included, and nothing while standing.
// (The adaptive detector, whose thresholds come from the steps before, missed exactly these.)

/// A foot-mounted IMU (medio-lateral axis y): `standing_s` still, then `normal` swings between
/// a small first and a small last one, each followed by a 0.6 s stance; then standing again.
/// A swing of duration T and rate amplitude A turns the foot -A T/pi then +A T/pi (toe-off,
/// swing), while its specific force leaves g by +-B (push-off, swing, impact).
std::vector<ImuSample> foot_walk(double rate_hz, int normal) {
  struct Swing {
    double t_s, a_rad_s, b_m_s2;
  };
  std::vector<Swing> swings;
  double t = 2.0;
  const auto add = [&](double dur, double a, double b) {
    swings.push_back({dur, a, b});
    t += dur + 0.6;
  };
  add(0.35, 2.0, 3.0);  // first step from standing: small
  for (int i = 0; i < normal; ++i) add(0.4, 6.0, 8.0);
  add(0.3, 2.0, 3.0);  // closing step
  std::vector<ImuSample> out;
  const double end = t + 2.0;
  std::size_t k = 0;
  double start = 2.0;
  for (int n = 0; n * (1.0 / rate_hz) < end; ++n) {
    const double ts = n / rate_hz;
    ImuSample s{ts, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, kG)};
    // A standing foot's noise: 0.01 rad/s, 0.03 m/s^2 (deterministic).
    s.gyro_body_rad_s += Eigen::Vector3d(0.01 * std::sin(37.0 * ts), 0.01 * std::cos(53.0 * ts), 0);
    s.acc_body_m_s2 += Eigen::Vector3d(0.03 * std::sin(41.0 * ts), 0.0, 0.03 * std::cos(29.0 * ts));
    while (k < swings.size() && ts > start + swings[k].t_s + 0.6) {
      start += swings[k].t_s + 0.6;
      ++k;
    }
    if (k < swings.size() && ts >= start && ts < start + swings[k].t_s) {
      const double tau = (ts - start) / swings[k].t_s;
      s.gyro_body_rad_s.y() += -swings[k].a_rad_s * std::sin(2.0 * M_PI * tau);
      s.acc_body_m_s2.x() += swings[k].b_m_s2 * std::sin(2.0 * M_PI * tau);
      s.acc_body_m_s2.z() += swings[k].b_m_s2 * std::sin(M_PI * tau);
    }
    out.push_back(s);
  }
  return out;
}

/// A lower-back IMU: standing, then `normal` steps at 1.8 Hz whose vertical acceleration swings
/// +-1.5 m/s^2 between a first step of +-`first` m/s^2 (starting: the IPOL lower-back trials'
/// first heel strikes load the trunk 0.47-1.1 times the walk's) and a last step of +-0.5 m/s^2
/// (stopping), standing. With `push`, the step is preceded by the first toe-off's push of gait
/// initiation, +-`push` m/s^2 (0.07-0.39 of the walk's there), and with `shift` that by the weight
/// shifted onto the stance leg, +-`shift`. The raw signal's peaks (the loading after each heel
/// strike) are at t0 + (i + 0.5) / 1.8 s, i = 0 .. normal + 1. The walk ends as the last loading
/// settles into standing, or, with `closing`, a quarter step later: at the last step's lowest
/// point, from which the closing heel strike's loading lifts the trunk to standing (by 0.5 m/s^2,
/// less than the walk's hysteresis, and without a fall after it).
constexpr double kTrunkT0 = 2.0, kTrunkHz = 1.8;
std::vector<ImuSample> trunk_walk(double rate_hz, int normal, double first = 0.8, double push = 0.0,
                                  double shift = 0.0, bool closing = false) {
  const int steps = normal + 2;
  const double f_hz = kTrunkHz, t0 = kTrunkT0, t1 = t0 + steps / f_hz;
  const double t_end = closing ? t1 + 0.25 / f_hz : t1 - 0.25 / f_hz;
  std::vector<ImuSample> out;
  for (int n = 0; n * (1.0 / rate_hz) < t1 + 2.0; ++n) {
    const double ts = n / rate_hz;
    // Tilted 20 deg: the vertical is not a sensor axis.
    const Eigen::Vector3d up(std::sin(0.35), 0.0, std::cos(0.35));
    double a = 0.03 * std::sin(31.0 * ts);
    if (ts >= t0 && ts < t_end) {
      const int i = std::min(static_cast<int>((ts - t0) * f_hz), steps - 1);
      const double amp = i == 0 ? first : i == steps - 1 ? 0.5 : 1.5;
      a += -amp * std::cos(2.0 * M_PI * f_hz * (ts - t0));
    } else if (ts >= t0 - 1.0 / f_hz && ts < t0) {
      a += -push * std::cos(2.0 * M_PI * f_hz * (ts - t0));
    } else if (ts >= t0 - 2.0 / f_hz && ts < t0 - 1.0 / f_hz) {
      a += -shift * std::cos(2.0 * M_PI * f_hz * (ts - t0));
    }
    ImuSample s{ts, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()),
                (kG + a) * up + Eigen::Vector3d(0.0, 0.2 * a, 0.0)};
    out.push_back(s);
  }
  return out;
}

std::size_t count_samples(StepDetector& d, const std::vector<ImuSample>& samples) {
  d.reset();
  std::size_t n = 0;
  StepEvent ev;
  for (const auto& s : samples) n += d.update(s, ev) ? 1u : 0u;
  while (d.flush(ev)) ++n;
  return n;
}

TEST(GaitPhaseStepDetector, FootCountsTheFirstStepFromStandingAndTheClosingStep) {
  for (double rate : {50.0, 100.0, 200.0}) {
    auto d = make_step_detector("gait-phase", StepMount::kFoot);
    EXPECT_EQ(count_samples(*d, foot_walk(rate, 8)), 10u) << rate << " Hz";
  }
}

TEST(GaitPhaseStepDetector, TrunkCountsTheFirstAndLastStepOfAWalk) {
  for (double rate : {50.0, 100.0, 200.0}) {
    auto d = make_step_detector("gait-phase", StepMount::kBody);
    EXPECT_EQ(count_samples(*d, trunk_walk(rate, 10)), 12u) << rate << " Hz";
  }
}

// Given a walk from standing that begins with the push of its first toe-off (the trunk lifted
// by a third of the walk's loading), when gait-phase counts a lower-back sensor's steps, then
// the push is no step: the walk's first step is held until the next three show what a step's
// loading is, and the push reaches less than 0.4 of it. Without the rule (first_step_fraction
// 0) the push counts. A walk of two steps keeps both (one to compare with, of the same size),
// and a stream ending while the first step is judged loses nothing (flush).
TEST(GaitPhaseStepDetector, TrunkDoesNotCountTheGaitInitiationPush) {
  for (double rate : {50.0, 100.0, 200.0}) {
    GaitPhaseStepParams p;
    p.mount = StepMount::kBody;
    GaitPhaseStepDetector d(p);
    EXPECT_EQ(count_samples(d, trunk_walk(rate, 10, 0.8, 0.5)), 12u) << rate << " Hz";
    EXPECT_EQ(d.diagnostics().rejected_amplitude, 1u) << rate << " Hz";
    p.first_step_fraction = 0.0;
    GaitPhaseStepDetector off(p);
    EXPECT_EQ(count_samples(off, trunk_walk(rate, 10, 0.8, 0.5)), 13u) << rate << " Hz";
    EXPECT_EQ(count_samples(d, trunk_walk(rate, 0, 1.5)), 2u) << rate << " Hz";
    // A stream that ends 0.3 s after a walk's third step: the first is still being judged, and
    // flush() judges it and releases all three.
    auto cut = trunk_walk(rate, 2, 1.5);
    std::erase_if(cut, [](const ImuSample& s) { return s.t_s > kTrunkT0 + 2.5 / kTrunkHz + 0.3; });
    EXPECT_EQ(count_samples(d, cut), 3u) << rate << " Hz";
  }
}

// Given a walk from standing that begins with two rises, the weight shifted onto the stance leg
// and then the push of the first toe-off (0.27 and 0.33 of the walk's loading), when gait-phase
// counts a lower-back sensor's steps, then neither is a step: the first is judged against the
// steps after it and dropped, and so is the next. Judging one only (first_steps_judged 1), the
// push counts.
TEST(GaitPhaseStepDetector, TrunkDoesNotCountTheWeightShiftBeforeThePush) {
  for (double rate : {50.0, 100.0, 200.0}) {
    GaitPhaseStepParams p;
    p.mount = StepMount::kBody;
    GaitPhaseStepDetector d(p);
    EXPECT_EQ(count_samples(d, trunk_walk(rate, 10, 1.5, 0.5, 0.4)), 12u) << rate << " Hz";
    EXPECT_EQ(d.diagnostics().rejected_amplitude, 2u) << rate << " Hz";
    p.first_steps_judged = 1;
    GaitPhaseStepDetector once(p);
    EXPECT_EQ(count_samples(once, trunk_walk(rate, 10, 1.5, 0.5, 0.4)), 13u) << rate << " Hz";
  }
}

// Given a walk that ends at the last step's lowest point, when gait-phase counts a lower-back
// sensor's steps, then the closing heel strike, whose loading lifts the trunk to standing by less
// than the walk's hysteresis and is followed by no fall, is a step (the IPOL lower-back trials
// missed it in 14 of 22 files); off (closing_rise_m_s2 0) it is lost. A trunk that comes to rest
// slowly after a walk (the vertical drifting back by 0.4 m/s^2 over a second, as the gravity
// estimate settles) makes no step, nor does standing on after the closing step.
TEST(GaitPhaseStepDetector, TrunkCountsTheClosingStepOfAWalk) {
  for (double rate : {50.0, 100.0, 200.0}) {
    GaitPhaseStepParams p;
    p.mount = StepMount::kBody;
    GaitPhaseStepDetector d(p);
    EXPECT_EQ(count_samples(d, trunk_walk(rate, 10, 0.8, 0.0, 0.0, true)), 13u) << rate << " Hz";
    p.closing_rise_m_s2 = 0.0;
    GaitPhaseStepDetector off(p);
    EXPECT_EQ(count_samples(off, trunk_walk(rate, 10, 0.8, 0.0, 0.0, true)), 12u) << rate << " Hz";
    auto drift = trunk_walk(rate, 10);
    const Eigen::Vector3d up(std::sin(0.35), 0.0, std::cos(0.35));
    const double settled = kTrunkT0 + 11.75 / kTrunkHz;
    for (auto& s : drift)
      if (s.t_s >= settled) s.acc_body_m_s2 -= 0.4 * std::exp(-(s.t_s - settled)) * up;
    EXPECT_EQ(count_samples(d, drift), 12u) << rate << " Hz";
  }
}

// Given a trunk whose loading peaks are known, when gait-phase reports a lower-back sensor's
// steps, then each is reported at its raw peak (the heel strike's loading): the 3 Hz low-pass's
// delay at the step frequency (0.09 s) taken off, within one sample interval and 0.01 s (a peak
// is found at a sample); the closing step, which has no peak, at the lowest point its heel strike
// ended, with the same delay taken off. In order, every step out once flush() has released the
// last held ones.
TEST(GaitPhaseStepDetector, TrunkReportsTheStepAtTheRawPeak) {
  for (double rate : {50.0, 100.0, 200.0}) {
    auto d = make_step_detector("gait-phase", StepMount::kBody);
    const auto samples = trunk_walk(rate, 10, 1.5, 0.0, 0.0, true);
    std::vector<double> times;
    StepEvent ev;
    for (const auto& s : samples)
      if (d->update(s, ev)) times.push_back(ev.t_s);
    while (d->flush(ev)) times.push_back(ev.t_s);
    ASSERT_EQ(times.size(), 13u) << rate << " Hz";
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double peak = kTrunkT0 + (static_cast<double>(i) + (i < 12 ? 0.5 : 0.0)) / kTrunkHz;
      EXPECT_NEAR(times[i], peak, 0.01 + 1.0 / rate) << rate << " Hz, step " << i;
    }
  }
}

// --- when a foot's step is reported ------------------------------------------------------------
// Given simulated people walking slowly, normally and fast (each heel strike known), when
// gait-phase counts their foot's steps, then it reports each one at the heel strike: half the
// detections within 0.03 s of it, three quarters within 0.04 s. The landing, reported before, came
// 0.05-0.13 s off, which put steps beside a U-turn on the wrong side of it in the IPOL recordings.
// (The simulated jog and run are left out: their foot stops turning ~0.1 s before it lands, so
// the swing, and with it the step, ends before the heel strike, with either time.)
TEST(GaitPhaseStepDetector, FootReportsTheHeelStrike) {
  for (const char* gait : {"slow-walk", "walk", "fast-walk"}) {
    std::vector<double> offsets;
    for (int p = 1; p <= 5; ++p) {
      const auto seed = static_cast<std::uint64_t>(p);
      const auto run =
          sim::simulate_gait(*sim::make_gait_scenario(std::string("foot-") + gait, seed),
                             sim::random_person(seed), seed);
      auto d = make_step_detector("gait-phase", StepMount::kFoot);
      StepEvent ev;
      for (const auto& s : run.samples) {
        if (!d->update(s.imu, ev)) continue;
        double best = 1e9;
        for (double hs : run.foot_step_times_s) best = std::min(best, std::abs(ev.t_s - hs));
        offsets.push_back(best);
      }
    }
    ASSERT_GT(offsets.size(), 100u) << gait;
    std::sort(offsets.begin(), offsets.end());
    const double median = offsets[offsets.size() / 2];
    const double p75 = offsets[offsets.size() * 3 / 4];
    EXPECT_LE(median, 0.03) << gait;
    EXPECT_LE(p75, 0.04) << gait;
    RecordProperty(std::string(gait) + "_median_ms", std::to_string(1000.0 * median));
  }
}

// A foot's strides at 100 Hz: stance, the push-off's toes-down run about the foot's y axis, the
// swing's toes-up run, the heel strike's impact, the slap back to flat. The stride `pivot` turns
// its foot on the ball first (toes down and about the vertical for 0.6 s, further along y than
// its swing turns up), as a walker does in a U-turn. Returns the samples; `strikes` the impacts.
std::vector<ImuSample> strides_with_a_pivot(int n, int pivot, std::vector<double>& strikes) {
  std::vector<ImuSample> out;
  double t = 0.0;
  const double dt = 0.01;
  const auto emit = [&](double dur, const auto& gyro, const auto& acc) {
    for (double t0 = t; t < t0 + dur - 1e-9; t += dt) {
      const double u = (t - t0) / dur;
      out.push_back({t, gyro(u), Eigen::Vector3d(0.0, 0.0, kG) + acc(u)});
    }
  };
  const auto still = [](double) { return Eigen::Vector3d(Eigen::Vector3d::Zero()); };
  emit(1.0, still, still);
  for (int k = 0; k < n; ++k) {
    const bool p = k == pivot;
    // The pivot turns the loaded foot about the vertical (z) at 3 rad/s into the swing's start,
    // its force off g all along: one motion with the swing, never still.
    const double push_s = p ? 0.6 : 0.1, push_rate = p ? 3.5 : 3.0, turn = p ? 3.0 : 0.0;
    emit(
        push_s,
        [&](double u) { return Eigen::Vector3d(0.0, -push_rate * std::sin(M_PI * u), turn); },
        [&](double u) { return Eigen::Vector3d(3.0 * std::sin(M_PI * u), 0.0, p ? 3.0 : 0.0); });
    emit(
        0.35,
        [&](double u) {
          return Eigen::Vector3d(0.0, 5.0 * std::sin(M_PI * u),
                                 turn * std::max(0.0, 1.0 - 4.0 * u));
        },
        [](double u) {
          return Eigen::Vector3d(6.0 * std::sin(2.0 * M_PI * u), 0.0, 2.0 * std::sin(M_PI * u));
        });
    strikes.push_back(t + 0.01);
    emit(
        0.06, [](double u) { return Eigen::Vector3d(0.0, -3.0 * std::sin(M_PI * u), 0.0); },
        [](double u) { return Eigen::Vector3d(0.0, 0.0, 15.0 * std::exp(-8.0 * u)); });
    emit(0.5, still, still);
  }
  emit(1.0, still, still);
  return out;
}

// Given a walk whose sixth stride begins with a pivot on the ball of the foot that turns the
// foot toes-down further than its swing then turns it up, when gait-phase counts it, then that
// step is reported at its heel strike (within 0.03 s), not at the end of the pivot: the swing's
// end is the end of its largest toes-up run, the sense learnt from the strides before
// (IPOL 2-3_lf's pivot in its U-turn). Every stride is one step. Seen failing with the sense not
// used (toes_up_sure 1e9): the pivot's step 0.31 s early.
TEST(GaitPhaseStepDetector, FootReportsAStepThatBeginsWithAPivotAtItsHeelStrike) {
  std::vector<double> strikes;
  const auto samples = strides_with_a_pivot(8, 5, strikes);
  GaitPhaseStepDetector d;
  std::vector<double> steps;
  StepEvent ev;
  for (const auto& s : samples)
    if (d.update(s, ev)) steps.push_back(ev.t_s);
  while (d.flush(ev)) steps.push_back(ev.t_s);
  ASSERT_EQ(steps.size(), strikes.size());
  for (std::size_t k = 0; k < steps.size(); ++k)
    EXPECT_NEAR(steps[k], strikes[k], 0.03) << "stride " << k;
}

// Given simulated walkers and joggers whose foot accelerometer reads 20 % low or 25 % high (a
// sensitivity or full-scale setting gone wrong; the IPOL left feet read 2-7 % high), when
// gait-phase counts their steps, then every step is counted: the foot's stance is judged against
// the accelerometer's own g, learnt while the foot does not turn. With g fixed at 9.81 m/s^2
// (g_tau_s 0) the swings of the sensor reading high never end and most steps are lost.
TEST(GaitPhaseStepDetector, FootCountsEveryStepWhateverItsAccelerometersScale) {
  for (const char* gait : {"walk", "jog"}) {
    for (int p = 1; p <= 3; ++p) {
      const auto seed = static_cast<std::uint64_t>(p);
      const auto run =
          sim::simulate_gait(*sim::make_gait_scenario(std::string("foot-") + gait, seed),
                             sim::random_person(seed), seed);
      for (double scale : {0.8, 1.25}) {
        std::vector<ImuSample> samples;
        for (const auto& s : run.samples) {
          samples.push_back(s.imu);
          samples.back().acc_body_m_s2 *= scale;
        }
        GaitPhaseStepDetector d;
        EXPECT_EQ(count_samples(d, samples), run.foot_step_times_s.size())
            << gait << " walker " << p << " scale " << scale;
      }
    }
  }
}

// --- real phone traces --------------------------------------------------------------------------
// Oxford step counter traces (CC BY 4.0, see tests/data/oxford_steps/README.md): 24 traces,
// 7 carrying positions, 3 phones, accelerometer only. Metric of the dataset: mean count accuracy.
// The full traces (../shared/data) give 98.21 %; these 50 Hz copies 98.22 (97.60 before the
// handled-phone rule, which the bound below would have failed). Every trace above 89 %: the
// swinging arm is the lowest (89.8 here, 90.8 full), its pendulum swamping the trunk's steps.
TEST(OxfordTraces, PeakValleyMeanCountAccuracyAtLeast98Percent) {
  const auto traces = read_oxford_traces();
  ASSERT_EQ(traces.size(), 24u);
  double sum = 0.0;
  for (const auto& trace : traces) {
    PeakValleyStepDetector d;
    std::size_t n = 0;
    for_each_step(d, trace.samples, [&n](const StepEvent&) { ++n; });
    const double acc = accuracy(n, trace.steps);
    EXPECT_GE(acc, 0.89) << trace.name << ": " << n << " of " << trace.steps;
    sum += acc;
  }
  RecordProperty("mean_accuracy_percent", std::to_string(100.0 * sum / 24.0));
  EXPECT_GE(sum / 24.0, 0.98);
}

}  // namespace
}  // namespace telltale::fusion
