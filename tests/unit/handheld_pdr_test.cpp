// HandheldPdr on the simulator's phone walks (sim/phone_walk.hpp), which carry what the IPIN
// 2023 walks showed (the real logs may not be copied here): a phone handled at random first,
// then held in front of a walker standing still, then a closed loop walked with the phone held
// in front, with pauses at corners. The gyro carries a constant bias.
#include "telltale/fusion/handheld_pdr.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "telltale/fusion/handheld/walk_steps.hpp"
#include "telltale/fusion/sim/phone_walk.hpp"

namespace {

using telltale::fusion::HandheldPdr;
using telltale::fusion::HandheldPdrParams;
using telltale::fusion::HandheldStep;
using telltale::fusion::ImuSample;

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kRate = 50.0;
using telltale::fusion::sim::PhoneSegment;
using telltale::fusion::sim::PhoneWalk;
using Phase = telltale::fusion::sim::PhonePhase;
using Segment = PhoneSegment;

Eigen::Matrix3d held_in_front(double heading, double extra_pitch = 0.0) {
  return telltale::fusion::sim::phone_held_in_front(heading, extra_pitch);
}

/// The IMU of a phone held as `r` (phone -> world) at `t`, turning to `r1` by `t + dt`: gravity
/// with 0.1 m/s^2 of noise per axis, the turn's rate plus `bias` with 0.005 rad/s of noise.
ImuSample held_sample(double t, double dt, const Eigen::Matrix3d& r, const Eigen::Matrix3d& r1,
                      const Eigen::Vector3d& bias, std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  ImuSample s;
  s.t_s = t;
  s.acc_body_m_s2 = r.transpose() * (Eigen::Vector3d(0.0, 0.0, kG) +
                                     0.1 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
  const Eigen::AngleAxisd d(Eigen::Matrix3d(r.transpose() * r1));
  s.gyro_body_rad_s = d.axis() * d.angle() / dt + bias +
                      0.005 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
  return s;
}

/// The simulator's phone walk at `step_hz`, its step the walk-ratio law's own at 1.75 m, so the
/// tests check the pipeline (counting, gating, heading), not the law.
PhoneWalk synthesise(const std::vector<Segment>& plan, const Eigen::Vector3d& gyro_bias,
                     unsigned seed, double step_hz = 1.8) {
  telltale::fusion::sim::PhoneWalkParams p;
  p.rate_hz = kRate;
  p.step_hz = step_hz;
  p.step_length_m = telltale::fusion::walk_ratio_step_length_m(1.75, step_hz);
  p.gyro_bias_rad_s = gyro_bias;
  return telltale::fusion::sim::simulate_phone_walk(plan, p, seed);
}

struct Run {
  std::vector<HandheldStep> steps;
  double heading_end_rad = 0.0;
};

Run run(const PhoneWalk& w, HandheldPdrParams p = {}) {
  p.orient_with_mag = false;
  HandheldPdr pdr(p);
  Run r;
  const Eigen::Vector3d no_mag = Eigen::Vector3d::Constant(std::nan(""));
  for (const auto& s : w.samples) {
    const int n = pdr.update(s, no_mag);
    for (int k = 0; k < n; ++k) r.steps.push_back(pdr.steps()[static_cast<std::size_t>(k)]);
  }
  r.heading_end_rad = pdr.heading_rad();
  return r;
}

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

// The lead-in of every IPIN log: handling, then standing. Nothing is a step.
// Seen failing: the seed-003 Pdr (the old `fusion_cli pdr`) counts 35-39 steps here; HandheldPdr
// with confirm_steps = 1 and the tilt and rate tests off (every bounce a step) 51-52; with
// min_swing_m_s2 = 0.05 (the hand's tremor a bounce) 16-27, all while standing.
TEST(HandheldPdr, HandlingAndStandingMakeNoSteps) {
  for (unsigned seed : {7u, 8u, 9u}) {
    const auto ws = synthesise({{Phase::kHandling, 30.0}, {Phase::kStanding, 30.0}},
                               Eigen::Vector3d(0.01, -0.008, 0.005), seed);
    const auto r = run(ws);
    EXPECT_EQ(r.steps.size(), 0u) << "seed " << seed << ": first at " << r.steps.front().t_s;
  }
}

/// Handling, standing, then a square loop of 4 legs with pauses of 5 s at two corners.
std::vector<Segment> loop_plan() {
  return {{Phase::kHandling, 30.0}, {Phase::kStanding, 30.0}, {Phase::kWalking, 20.0, 0.0},
          {Phase::kPause, 5.0},     {Phase::kWalking, 20.0, 90.0}, {Phase::kWalking, 20.0, 90.0},
          {Phase::kPause, 8.0, 45.0}, {Phase::kWalking, 20.0, 45.0}, {Phase::kStanding, 10.0}};
}

// Given a phone sampled at 50, 100, 200 and 400 Hz (phones run their sensors at any of these),
// then the walk detector's windows span the same seconds at every rate: the vertical force's
// mean over mean_s and its smoothing over smooth_s. Seen failing with its rings at 256 and 32
// samples, which a full ring cut short above 128 / 160 Hz (at 400 Hz a 0.64 s mean and a 0.08 s
// smoothing); on the IPIN walks resampled to 200 Hz (`steps-eval --rate-hz 200`) that counted 3
// more steps on every walk of route 01 and walked 4 % farther.
TEST(WalkStepDetector, ItsWindowsSpanTheirSecondsAt50To400Hz) {
  const telltale::fusion::WalkStepParams p;
  for (double rate : {50.0, 100.0, 200.0, 400.0}) {
    telltale::fusion::WalkStepDetector d(p);
    ImuSample s;
    for (int i = 0; i <= static_cast<int>(3.0 * rate); ++i) {
      s.t_s = i / rate;
      s.acc_body_m_s2 = {0.0, 0.0, kG + 2.0 * std::sin(2.0 * M_PI * 1.8 * s.t_s)};
      d.update(s, Eigen::Vector3d::UnitZ());
    }
    const auto& st = d.state();
    const auto newest = [](const auto& ring, std::size_t head, std::size_t size) {
      return ring[(head + size - 1) % ring.size()];
    };
    const double mean_span = newest(st.ring_t, st.head, st.size) - st.ring_t[st.head];
    const double smooth_span = newest(st.sm_t, st.sm_head, st.sm_size) - st.sm_t[st.sm_head];
    // The mean: every sample up to mean_s old; the smoothing: those younger than smooth_s, n
    // samples spanning n - 1 intervals.
    EXPECT_NEAR(mean_span, p.mean_s, 0.5 / rate) << rate << " Hz";
    EXPECT_NEAR(smooth_span + 1.0 / rate, p.smooth_s, 0.5 / rate) << rate << " Hz";
  }
}

// Given a phone handled at random for its first seconds (turns of 2-7 rad/s, the hand's
// jerks), then the PDR's attitude filter, which is the boat's with its defaults (no platform
// rule), never runs its start's line fit: it has no GNSS speed, the only evidence of a hull in a
// seaway that the fit models (a handled phone's turns read as a gyro bias by the fit cost the
// IPIN walks 4.25 -> 5.90 % of loop closure). Seen failing against the filter whose fit ran
// from the first sample, which the hand-held PDR turned off by a parameter of its own.
TEST(HandheldPdr, AttitudeFilterWithoutGnssNeverFitsTheStartLine) {
  EXPECT_EQ(HandheldPdrParams{}.attitude.start_fit_s,
            telltale::fusion::TelltaleAttitudeParams{}.start_fit_s);
  for (unsigned seed : {31u, 32u, 33u}) {
    const auto w = synthesise(loop_plan(), Eigen::Vector3d(0.01, -0.008, 0.005), seed);
    telltale::fusion::TelltaleAttitudeFilter f(HandheldPdrParams{}.attitude);
    int k = 0;
    for (const auto& s : w.samples) {
      if (s.t_s > 15.0) break;
      f.update(s);
      ++k;
      ASSERT_FALSE(f.state().start_fit) << "seed " << seed << " sample " << k;
    }
    EXPECT_GT(k, 500);
  }
}

// A walk with pauses: no step in any pause (beyond the step that ends the walking), the count and
// the distance within 3 % of the truth (the model's length is the truth's: this checks counting).
// Seen failing: the seed-003 Pdr counts 34-37 steps too many (29-35 m too far), 108 of them in
// the handling, standing and pauses; HandheldPdr with min_swing_m_s2 = 0.05 puts 119 steps there.
TEST(HandheldPdr, WalkWithPausesCountsOnlyWalking) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const auto w = synthesise(loop_plan(), Eigen::Vector3d(0.01, -0.008, 0.005), seed);
    const auto r = run(w);
    ASSERT_FALSE(r.steps.empty());
    const double interval = 1.0 / 1.8;
    for (const auto& s : r.steps)
      for (const auto& q : w.truth.quiet)
        EXPECT_FALSE(s.t_s > q.first + interval && s.t_s < q.second)
            << "seed " << seed << ": step at " << s.t_s << " in [" << q.first << ", " << q.second
            << "]";
    const double steps = static_cast<double>(r.steps.size());
    EXPECT_NEAR(steps, w.truth.steps, 0.03 * w.truth.steps) << "seed " << seed;
    EXPECT_NEAR(r.steps.back().distance_m, w.truth.distance_m, 0.03 * w.truth.distance_m)
        << "seed " << seed;
  }
}

// A walk from standing begins with the push of its first toe-off (the simulator's walker, as the
// IPOL lower-back trials show it: a quarter of a heel strike's loading, a step interval before
// the first heel strike, in the walk's rhythm). The loop's three walks from standing or a pause
// count their heel strikes, no more, and none before the first, nor fewer: a bounce of the
// hand while standing a second before the first step does not cost that step.
// Seen failing with first_step_fraction 0: 146-147 steps for 144, the first at the walk's start;
// and with a run that broke its rhythm dropped whole (the candidate before the break not kept as
// the start of the next): seed 12 143, its first step the second of a run begun by the hand.
TEST(HandheldPdr, ThePushOfTheFirstToeOffIsNoStep) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const auto w = synthesise(loop_plan(), Eigen::Vector3d(0.01, -0.008, 0.005), seed);
    const auto r = run(w);
    ASSERT_FALSE(r.steps.empty());
    EXPECT_EQ(static_cast<double>(r.steps.size()), std::round(w.truth.steps)) << "seed " << seed;
    EXPECT_GT(r.steps.front().t_s, w.truth.walk_start_s + 0.5 / 1.8) << "seed " << seed;
  }
}

// The closing step of a walk, the heel strike that brings the walker to rest, comes in the walk's
// rhythm, but its loading may settle slowly (the phone's vertical falls under its 2 s mean only
// ~0.9 s after the peak here). The walk is not over while a peak found in its rhythm still
// awaits its valley: 8 steps and the closing one counted. Seen failing with the pause test on
// the clock alone (the walk ended 1.2 s after its last step, the closing one then the first of
// a run that never came): 8 steps.
TEST(WalkStepDetector, AClosingStepWhoseLoadingSettlesSlowlyIsCounted) {
  telltale::fusion::WalkStepDetector d;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const double period = 0.6, t0 = 5.0, t_close = t0 + 8.0 * period;
  const auto vertical = [&](double t) {
    if (t < t0) return 0.0;
    if (t < t_close) return 2.0 * std::cos(2.0 * M_PI * (t - t0) / period);  // peaks at t0 + k T
    if (t < t_close + 1.6) return 0.8 * std::cos(M_PI * (t - t_close) / 1.6);
    if (t < t_close + 2.6) return -0.8 * (1.0 - (t - t_close - 1.6));  // back to standing
    return 0.0;
  };
  int counted = 0;
  for (int i = 0; i < 50 * 15; ++i) {
    ImuSample s;
    s.t_s = i / 50.0;
    s.acc_body_m_s2 = Eigen::Vector3d(0.0, 0.0, kG + vertical(s.t_s));
    s.gyro_body_rad_s.setZero();
    counted += d.update(s, up);
  }
  EXPECT_EQ(counted, 9);
}

// A constant gyro bias of (0.01, -0.008, 0.005) rad/s: 0.17 deg/s about the vertical of a phone
// held in front (and 0.7 deg/s in all), 19 deg over the walk. Learnt while standing (30 s, with
// the hand's tremor and a +-1.5 deg yaw wander), the heading at the end is within 3 deg of the
// truth and the end point within 3 % of the distance walked of the true end.
// Seen failing: the seed-003 Pdr ends 9-88 deg and 32-39 m off; HandheldPdr with the stand
// learner off (min_stand_s = 1e9) 18-19 deg and 5.1 m (bound 3.2 m); the control below checks
// that the bias is large enough to matter.
TEST(HandheldPdr, GyroBiasLearntWhileStandingBoundsHeadingDrift) {
  const Eigen::Vector3d bias(0.01, -0.008, 0.005);
  for (unsigned seed : {21u, 22u, 23u}) {
    const auto w = synthesise(loop_plan(), bias, seed);
    const auto r = run(w);
    ASSERT_FALSE(r.steps.empty());
    // The track starts north (no magnetometer): compare turns since the walk began.
    const double start_truth = 0.3;
    const double start_est = r.steps.front().heading_deg * M_PI / 180.0;
    const double err = wrap((r.heading_end_rad - start_est) - (w.truth.heading_rad - start_truth));
    EXPECT_LT(std::fabs(err) * 180.0 / M_PI, 3.0) << "seed " << seed;
    // End point: the estimated track rotated onto the truth's start direction.
    const double rot = start_truth - start_est;
    const auto& e = r.steps.back();
    const double x = e.x_m * std::cos(rot) + e.y_m * std::sin(rot);
    const double y = -e.x_m * std::sin(rot) + e.y_m * std::cos(rot);
    EXPECT_LT(std::hypot(x - w.truth.x_m, y - w.truth.y_m), 0.03 * w.truth.distance_m)
        << "seed " << seed << ": end " << x << ", " << y << " truth " << w.truth.x_m << ", "
        << w.truth.y_m;
    // Control: without the stand's bias the same walk drifts far beyond the bound.
    HandheldPdrParams off;
    off.bias.max_bias_rad_s = 0.0;
    const auto r0 = run(w, off);
    const double s0 = r0.steps.front().heading_deg * M_PI / 180.0;
    const double err0 = wrap((r0.heading_end_rad - s0) - (w.truth.heading_rad - start_truth));
    EXPECT_GT(std::fabs(err0) * 180.0 / M_PI, 10.0) << "seed " << seed;
  }
}

}  // namespace

namespace {

using telltale::fusion::StandBiasLearner;

/// A walker standing 20 s with the phone held in front: its yaw wanders 10 deg (a 30 s sine, so
/// the stand ends 8.7 deg away from where it began: what the real stands showed), the hand's
/// tremor on top; a constant gyro bias; a fixed magnetic field bent by indoor iron (not north,
/// its horizontal part 18 uT), with 0.4 uT noise per axis. Returns the learner's vertical bias
/// error (rad/s) about the stand's vertical.
double stand_bias_error(bool use_mag, unsigned seed, const Eigen::Vector3d& bias,
                        double field_step_uT = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  telltale::fusion::StandBiasParams p;
  p.mag_yaw_bias = use_mag;
  StandBiasLearner learner(p);
  const double dt = 1.0 / kRate;
  const Eigen::Vector3d field_world(-11.0, 14.0, -38.0);  // ENU, disturbed: points north-west
  auto rot_at = [](double t) {
    const double wander = 10.0 * M_PI / 180.0 * std::sin(2.0 * M_PI * t / 30.0);
    const double tremor = 0.005 * std::sin(2.0 * M_PI * 8.0 * t);
    return held_in_front(1.1 + wander, tremor);
  };
  Eigen::Vector3d up_mean = Eigen::Vector3d::Zero();
  const int n = static_cast<int>(20.0 * kRate);
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt;
    const Eigen::Matrix3d r = rot_at(t), r1 = rot_at(t + dt);
    ImuSample s = held_sample(t, dt, r, r1, bias, rng);
    // A magnet coming near the phone in the second half (the field is then not one fixed
    // vector): field_step_uT more downward and half of it east by the end.
    const Eigen::Vector3d extra =
        t > 10.0 ? Eigen::Vector3d(Eigen::Vector3d(0.5, 0.0, -1.0) * field_step_uT * (t - 10.0) / 10.0)
                 : Eigen::Vector3d::Zero();
    const Eigen::Vector3d mag = r.transpose() * (field_world + extra) +
                                0.4 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const Eigen::Vector3d up = r.transpose() * Eigen::Vector3d::UnitZ();
    up_mean += up;
    learner.update(s, up, mag);
  }
  const Eigen::Vector3d u = up_mean.normalized();
  return (learner.bias_rad_s() - bias).dot(u);
}

constexpr double kDegS = M_PI / 180.0;

// The bias about the vertical from a stand with the field: within 0.03 deg/s (the heading then
// drifts under 2.5 deg over an 80 s out-and-back leg, what a 2 % loop closure needs), whatever
// the 8.7 deg net yaw wander.
// Seen failing: with mag_yaw_bias = false (the gyro-only learner) the same stands are 0.43-0.44
// deg/s off (checked below as the control); with the magnetic yaw's sign flipped (psi_m = +h)
// 1.31 deg/s.
TEST(StandBiasLearner, MagneticYawOverAStandGivesTheVerticalBias) {
  const Eigen::Vector3d bias(0.004, -0.006, 0.005);
  for (unsigned seed : {31u, 32u, 33u}) {
    const double err = stand_bias_error(true, seed, bias);
    EXPECT_LT(std::fabs(err), 0.03 * kDegS) << "seed " << seed << ": " << err / kDegS << " deg/s";
    const double err0 = stand_bias_error(false, seed, bias);
    EXPECT_GT(std::fabs(err0), 0.3 * kDegS) << "seed " << seed << ": " << err0 / kDegS;
  }
}

// A field that changes during the stand (a magnet coming near: |B| grows 7 uT, the horizontal part turns 12 deg) is not a fixed
// vector: the stand gives no magnetic estimate and the learner keeps the gyro's.
// Seen failing: with max_mag_norm_sd_uT = 1e9 the slope is taken and is 0.53-0.54 deg/s off
// (the gyro's own estimate: 0.43-0.45).
TEST(StandBiasLearner, ChangingFieldGivesNoMagneticEstimate) {
  const Eigen::Vector3d bias(0.004, -0.006, 0.005);
  for (unsigned seed : {41u, 42u}) {
    const double with_step = stand_bias_error(true, seed, bias, 8.0);
    const double gyro_only = stand_bias_error(false, seed, bias, 8.0);
    EXPECT_NEAR(with_step, gyro_only, 1e-12) << "seed " << seed;
  }
}

/// Two stands with handling between them, each giving a magnetic slope: 0-8 s with the field's
/// direction swinging about the vertical by `swing_deg` (a sine over the 8 s: the hand moving
/// the phone through an indoor gradient; |B| stays the same, so the |B| test passes), then
/// 4 s of the phone turned back and forth (2.5 rad/s: not a stand), then 25 s with a fixed
/// field. Returns the learner's vertical bias error (rad/s) at the end.
double two_stand_bias_error(unsigned seed, const Eigen::Vector3d& bias, double swing_deg) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  StandBiasLearner learner{telltale::fusion::StandBiasParams{}};
  const double dt = 1.0 / kRate;
  const Eigen::Vector3d field_world(-11.0, 14.0, -38.0);
  const double w0 = 3.0 * M_PI / 180.0 * std::sin(2.0 * M_PI * 8.0 / 30.0);
  auto heading_at = [&](double t) {
    if (t < 8.0) return 1.1 + 3.0 * M_PI / 180.0 * std::sin(2.0 * M_PI * t / 30.0);
    if (t < 12.0) return 1.1 + w0 + 0.8 * std::sin(2.0 * M_PI * (t - 8.0) / 2.0);
    return 1.1 + w0 + 3.0 * M_PI / 180.0 * std::sin(2.0 * M_PI * (t - 12.0) / 30.0);
  };
  auto rot_at = [&](double t) {
    return held_in_front(heading_at(t), 0.005 * std::sin(2.0 * M_PI * 8.0 * t));
  };
  Eigen::Vector3d up_mean = Eigen::Vector3d::Zero();
  const int n = static_cast<int>(37.0 * kRate);
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt;
    const Eigen::Matrix3d r = rot_at(t), r1 = rot_at(t + dt);
    ImuSample s = held_sample(t, dt, r, r1, bias, rng);
    const double bend =
        t < 8.0 ? swing_deg * M_PI / 180.0 * std::sin(2.0 * M_PI * t / 8.0) : 0.0;
    const Eigen::Vector3d field = Eigen::AngleAxisd(bend, Eigen::Vector3d::UnitZ()) * field_world;
    const Eigen::Vector3d mag =
        r.transpose() * field + 0.4 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const Eigen::Vector3d up = r.transpose() * Eigen::Vector3d::UnitZ();
    if (t >= 12.0) up_mean += up;
    learner.update(s, up, mag);
  }
  return (learner.bias_rad_s() - bias).dot(up_mean.normalized());
}

// Stands are combined by the inverse variance of their slopes (T^3 / residual variance about
// the line): a short stand whose field wandered hardly moves the estimate of a long clean one.
// Within 0.03 deg/s, as for one clean stand above (measured 0.014-0.024 deg/s; with both
// stands clean 0.004-0.015).
// Seen failing: with each stand weighted by T^2 (the weighting before) 0.13-0.15 deg/s off on
// these seeds (0.07-0.08 with a 3 deg swing).
TEST(StandBiasLearner, LongCleanStandOutweighsAShortWanderingOne) {
  const Eigen::Vector3d bias(0.004, -0.006, 0.005);
  for (unsigned seed : {51u, 52u, 53u}) {
    const double err = two_stand_bias_error(seed, bias, 6.0);
    EXPECT_LT(std::fabs(err), 0.03 * kDegS) << "seed " << seed << ": " << err / kDegS << " deg/s";
  }
}

}  // namespace

// The walk-ratio law: the population norm it is anchored on (a step of 0.415 x height at
// 112 steps/min), the step in proportion to cadence and to height. Seed 003's simulator-fitted
// line gave 0.69 m at 1.6 steps/s and 1.75 m, against the 0.58-0.61 m of real phone walks there.
TEST(WalkRatio, StepLengthFollowsTheWalkRatioOfPeople) {
  using telltale::fusion::walk_ratio_step_length_m;
  EXPECT_NEAR(walk_ratio_step_length_m(1.75, 112.0 / 60.0), 0.415 * 1.75, 0.005);
  EXPECT_NEAR(walk_ratio_step_length_m(1.75, 1.6), 0.62, 0.01);
  EXPECT_NEAR(walk_ratio_step_length_m(1.75, 2.0) / walk_ratio_step_length_m(1.75, 1.5),
              2.0 / 1.5, 1e-12);
  EXPECT_NEAR(walk_ratio_step_length_m(1.60, 1.8) / walk_ratio_step_length_m(1.90, 1.8),
              1.60 / 1.90, 1e-12);
}

// relay_track on a walk north at a constant true heading, 1 step/s, phone flat (up = z): the
// live track laid its first 50 s with a bias 0.01 rad/s too large about the vertical (a bad
// first stand), the rest with the true bias. Live, the heading drifted 0.5 rad over those 50 s.
std::vector<HandheldStep> drifting_walk() {
  std::vector<HandheldStep> steps;
  double bias_yaw = 0.0, x = 0.0, y = 0.0;
  for (int k = 0; k < 100; ++k) {
    const double t = k;
    if (k > 0 && t <= 50.0) bias_yaw += 0.01;  // (b in use) . up over the second before
    HandheldStep s;
    s.t_s = t;
    s.length_m = 0.7;
    const double heading = bias_yaw;  // heading = offset - yaw, yaw = -bias_yaw (true rate 0)
    x += s.length_m * std::sin(heading);
    y += s.length_m * std::cos(heading);
    s.x_m = x;
    s.y_m = y;
    s.heading_deg = heading * 180.0 / M_PI;
    s.gyro = {t, s.length_m, heading, bias_yaw, Eigen::Vector3d(0.0, 0.0, t)};
    steps.push_back(s);
  }
  return steps;
}

// Seen failing with relay_track a no-op: the walk ends 20.8 m east of its line.
TEST(RelayTrack, TheWalksFinalBiasTakesTheFirstStandsErrorOffEveryStep) {
  auto steps = drifting_walk();
  EXPECT_GT(steps.back().x_m, 10.0);                              // the live track's drift
  telltale::fusion::relay_track(steps, Eigen::Vector3d::Zero());  // the true bias, learnt later
  for (const auto& s : steps) {
    EXPECT_NEAR(s.x_m, 0.0, 1e-9) << s.t_s;
    EXPECT_NEAR(s.heading_deg, 0.0, 1e-9) << s.t_s;
  }
  EXPECT_NEAR(steps.back().y_m, 70.0, 1e-9);
  EXPECT_DOUBLE_EQ(steps.back().length_m, 0.7);
}

// Laid again with the bias it was laid with all along, a walk does not move.
TEST(RelayTrack, TheBiasInUseAllAlongLeavesTheTrackAsItWas) {
  auto steps = drifting_walk();
  for (auto& s : steps) s.gyro.bias_yaw_rad = 0.003 * s.t_s;  // 0.003 rad/s in use from the start
  const auto before = steps;
  telltale::fusion::relay_track(steps, Eigen::Vector3d(0.0, 0.0, 0.003));
  for (std::size_t k = 0; k < steps.size(); ++k) {
    EXPECT_NEAR(steps[k].x_m, before[k].x_m, 1e-9);
    EXPECT_NEAR(steps[k].y_m, before[k].y_m, 1e-9);
  }
}

/// drifting_walk() through a TrackRelay, the bias known to it at each step `known(t)`: the last
/// step as laid, `check(step, laid)` run on every step.
using Laid = telltale::fusion::TrackRelay::Laid;
Laid lay_walk(telltale::fusion::TrackRelay& relay,
              const std::function<Eigen::Vector3d(double)>& known,
              const std::function<void(const HandheldStep&, const Laid&)>& check = {}) {
  Laid laid;
  for (const auto& s : drifting_walk()) {
    laid = relay.lay(s.gyro, known(s.t_s));
    if (check) check(s, laid);
  }
  return laid;
}

/// The bias a stand at 50 s measures: 0.01 rad/s too large before it, the truth (0) after.
Eigen::Vector3d stand_at_50_s(double t) {
  return t <= 50.0 ? Eigen::Vector3d(0.0, 0.0, 0.01) : Eigen::Vector3d::Zero();
}

// The live track (TrackRelay) on the same walk, its bias known wrong (0.01 rad/s) until a stand at
// 50 s measures it (0): up to the stand each step lies where the gyro laid it, from the first
// step after it on the track is the one relay_track lays with the true bias: the position jumps
// back onto the line and stays there. Seen failing with lay() adding each step with the bias
// known at it and leaving the steps before it where they were (9.1 m east after the stand).
TEST(TrackRelay, AStandsBiasLaysTheStepsBeforeItAgain) {
  telltale::fusion::TrackRelay relay;
  lay_walk(relay, stand_at_50_s, [](const HandheldStep& s, const Laid& laid) {
    if (s.t_s <= 50.0) {
      EXPECT_NEAR(laid.x_m, s.x_m, 1e-9) << s.t_s;  // the bias in use all along: as laid
      EXPECT_NEAR(laid.y_m, s.y_m, 1e-9) << s.t_s;
    } else {
      EXPECT_NEAR(laid.x_m, 0.0, 1e-9) << s.t_s;
      EXPECT_NEAR(laid.y_m, 0.7 * (s.t_s + 1.0), 1e-9) << s.t_s;
      EXPECT_NEAR(laid.heading_rad, 0.0, 1e-9) << s.t_s;
    }
  });
}

// A bias that is not finite is no measurement: the track goes on with the last one (NaN would
// make every position NaN from then on). Seen failing without the check: x NaN.
TEST(TrackRelay, ANonFiniteBiasKeepsTheLastOne) {
  telltale::fusion::TrackRelay relay;
  const Laid last = lay_walk(relay, [](double t) {
    return t <= 50.0 ? Eigen::Vector3d(0.0, 0.0, 0.01)
                     : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  });
  EXPECT_TRUE(std::isfinite(last.x_m) && std::isfinite(last.y_m));
}

// Steps older than the window keep where they were laid (the bias they were walked with has
// drifted since): with a 20 s window the stand at 50 s mends only the 20 steps before it, and
// the first 30 keep the 0.3 rad their live heading had drifted to. Seen failing with the window
// ignored (the walk back on the line, x 0).
TEST(TrackRelay, StepsOlderThanTheWindowKeepWhereTheyWereLaid) {
  telltale::fusion::TrackRelay relay(20.0);
  const Laid last = lay_walk(relay, stand_at_50_s);
  // Steps 0-30 (more than 20 s before the stand's first step, at 51 s) where the gyro laid them
  // with the wrong bias, the later ones on the line.
  double x = 0.0;
  for (const auto& s : drifting_walk())
    if (s.t_s < 31.0) x += s.length_m * std::sin(s.gyro.gyro_heading_rad);
  EXPECT_GT(x, 2.0);
  EXPECT_NEAR(last.x_m, x, 1e-9);
}

namespace {

// The simulated counterpart of an IPIN walk (steps-eval's table beside the real ones): handling
// and standing first (nothing walked), then a rectangle that closes on itself, the same samples
// for the same seed. Seen failing with the plan's first leg left out (the walk ends 8-25 m from
// its start).
TEST(PhoneWalkSim, IpinLikePlanIsAClosedWalkAfterHandlingAndStanding) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    telltale::fusion::sim::PhoneWalkParams p;
    const auto plan = telltale::fusion::sim::ipin_like_plan(seed, 1.75, p);
    const auto w = telltale::fusion::sim::simulate_phone_walk(plan, p, seed);
    ASSERT_EQ(w.samples.size(), w.mag_uT.size());
    EXPECT_GE(w.truth.walk_start_s, 40.0) << "seed " << seed;
    ASSERT_GE(w.truth.quiet.size(), 2u);
    EXPECT_DOUBLE_EQ(w.truth.quiet[1].second, w.truth.walk_start_s);
    // The sides are whole steps, the same count for the two sides of a length; the three
    // corners are quarter circles walked at full speed over 1.5 s (radius r = v 1.5 s / (pi / 2)),
    // each ending r (1, 1 - pi / 2) off a sharp corner's path, and turned by 90 deg from the one
    // before: together (1, 1 - pi / 2) + (pi / 2 - 1, 1) - (1, 1 - pi / 2) = r (pi / 2 - 1, 1),
    // 1.15 r from the start (1.17 r sampled at 50 Hz).
    const double r = p.step_length_m * p.step_hz * 1.5 / M_PI_2;
    EXPECT_LT(std::hypot(w.truth.x_m, w.truth.y_m), 1.2 * r) << "seed " << seed;
    EXPECT_GT(w.truth.distance_m, 32.0);
    EXPECT_NEAR(w.truth.steps, w.truth.distance_m / p.step_length_m, 1e-6 * w.truth.steps);
    const auto again = telltale::fusion::sim::simulate_phone_walk(plan, p, seed);
    EXPECT_EQ(again.samples.back().gyro_body_rad_s, w.samples.back().gyro_body_rad_s);
  }
}

}  // namespace
