// Heading fusion (paper 002): the "Must show" items, analytic invariants, seeded sweeps
// and Given/When/Then scenarios on the simulator.
#include "telltale/fusion/heading_fusion.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "telltale/fusion/sim/heading_eval.hpp"
#include "telltale/fusion/sim/heading_sim.hpp"

namespace telltale::fusion {
namespace {

using sim::HeadingRunResult;
using sim::HeadingScenario;
using sim::HeadingSimSample;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

HeadingScenario scenario(const std::string& name) {
  auto sc = sim::heading_scenario(name);
  EXPECT_TRUE(sc.has_value()) << name;
  return *sc;
}

HeadingRunResult run(const HeadingScenario& sc, const std::vector<HeadingSimSample>& samples,
                     HeadingMethod m) {
  HeadingFusionParams p = sc.fusion;
  p.method = m;
  return sim::run_heading(sc, samples, p);
}

/// Chi-square quantile (Wilson-Hilferty; better than 0.5 % for dof >= 30, which is all we use).
double chi2_quantile(double dof, double z_normal) {
  const double a = 2.0 / (9.0 * dof);
  const double c = 1.0 - a + z_normal * std::sqrt(a);
  return dof * c * c * c;
}

// ---------------------------------------------------------------- paper's setup (Must show 1)

class PaperSetup : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(PaperSetup, ClosedLoopBeatsDistributedAndBestSingleAndMatchesCentralized) {
  // Given the paper's test: N = 3, T = 0.1 s, Q = 0.3, r_i = 0.01, a small- or large-change profile
  const auto& [name, seed] = GetParam();
  const HeadingScenario sc = scenario(name);
  const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(seed));
  // When every method runs on the same readings
  const auto cl = run(sc, samples, HeadingMethod::kClosedLoop);
  const auto dist = run(sc, samples, HeadingMethod::kDistributed);
  const auto cen = run(sc, samples, HeadingMethod::kCentralized);
  const auto best = run(sc, samples, HeadingMethod::kBestSingle);
  std::cout << name << " seed " << seed << ": closed-loop " << cl.rms_deg << " distributed "
            << dist.rms_deg << " centralized " << cen.rms_deg << " best-single " << best.rms_deg
            << " deg RMS\n";
  // Then closed-loop is below distributed and the best single sensor, within 5 % of centralized
  EXPECT_LT(cl.rms_deg, dist.rms_deg);
  EXPECT_LT(cl.rms_deg, 0.85 * best.rms_deg);
  EXPECT_LT(std::abs(cl.rms_deg / cen.rms_deg - 1.0), 0.05);
  // and the fused error is of the size the three sensors allow (0.1 / sqrt(3) = 0.058 deg)
  EXPECT_LT(cl.rms_deg, 0.058);
}

INSTANTIATE_TEST_SUITE_P(Seeds, PaperSetup,
                         ::testing::Combine(::testing::Values("paper-small", "paper-large"),
                                            ::testing::Values(1, 2, 3, 4, 5)));

TEST(HeadingClosedLoop, EqualsCentralizedStepByStepOnIdenticalSynchronousSensors) {
  // Given identical sensors reporting together (the paper's case), fault handling off
  HeadingScenario sc = scenario("paper-model");
  sc.fusion.monitor.enabled = false;
  const auto samples = sim::simulate_heading(sc, 7);
  HeadingFusionParams pc = sc.fusion;
  HeadingFusionParams pz = sc.fusion;
  pc.method = HeadingMethod::kClosedLoop;
  pz.method = HeadingMethod::kCentralized;
  HeadingFusion cl(pc);
  HeadingFusion cen(pz);
  double worst = 0.0;
  for (const auto& s : samples) {
    cl.update(s.t_s, s.reading_deg.data());
    cen.update(s.t_s, s.reading_deg.data());
    worst = std::max(worst, std::abs(wrap_180_deg(cl.heading_deg() - cen.heading_deg())));
    worst = std::max(worst, (cl.state().p - cen.state().p).cwiseAbs().maxCoeff());
  }
  // Then the resolved closed loop is the centralized filter (to rounding)
  EXPECT_LT(worst, 1e-9);
  // and its information shares are beta_i = 1/3 (eq. 35-36 at their fixed point)
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(cl.state().beta[static_cast<std::size_t>(i)], 1.0 / 3, 1e-12);
}

TEST(HeadingClosedLoop, UnequalSensorsStayWithinFivePercentOfCentralized) {
  // Given sensors of 0.05, 0.1 and 0.3 deg on the large-change profile
  HeadingScenario sc = scenario("paper-large");
  const std::array<double, 3> sd{0.05, 0.1, 0.3};
  for (std::size_t i = 0; i < 3; ++i) {
    sc.sensors[i].noise_deg = sd[i];
    sc.fusion.noise_deg[i] = sd[i];
  }
  for (int seed = 1; seed <= 3; ++seed) {
    const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(seed));
    const auto cl = run(sc, samples, HeadingMethod::kClosedLoop);
    const auto cen = run(sc, samples, HeadingMethod::kCentralized);
    const auto best = run(sc, samples, HeadingMethod::kBestSingle);
    EXPECT_LT(std::abs(cl.rms_deg / cen.rms_deg - 1.0), 0.05) << "seed " << seed;
    EXPECT_LT(cl.rms_deg, best.rms_deg) << "seed " << seed;
  }
}

TEST(HeadingClosedLoopPaper, PrintedLambdaIsBiasedTowardsZeroDegrees) {
  // Given a boat holding 200 deg and three perfect compasses
  for (HeadingMethod m : {HeadingMethod::kClosedLoopPaper, HeadingMethod::kClosedLoop}) {
    HeadingFusionParams p = HeadingFusionParams::paper();
    p.method = m;
    p.monitor.enabled = false;
    HeadingFusion f(p);
    const std::array<double, 3> y{200.0, 200.0, 200.0};
    for (int k = 0; k < 600; ++k) f.update(0.1 * k, y.data());
    // Then eq. 33 with eq. 32's lambda settles away from 200 deg (D sum lambda_i != I), and the
    // resolved form settles on it
    const double err = std::abs(wrap_180_deg(f.heading_deg() - 200.0));
    if (m == HeadingMethod::kClosedLoopPaper) {
      EXPECT_GT(err, 5.0) << "printed eq. 33 unexpectedly unbiased";
    } else {
      EXPECT_LT(err, 1e-9);
    }
  }
}

// ---------------------------------------------------------------- consistency (Must show 3)

TEST(HeadingConsistency, NeesInside95PercentBandWhenTheModelIsRight) {
  // Given M runs of the paper's model itself (truth drawn from F, G, Q), no fault
  const HeadingScenario sc = scenario("paper-model");
  constexpr int kRuns = 30;
  std::vector<double> nees_sum;
  for (int seed = 1; seed <= kRuns; ++seed) {
    const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(100 + seed));
    const auto r = run(sc, samples, HeadingMethod::kClosedLoop);
    if (nees_sum.empty()) nees_sum.assign(r.nees.size(), 0.0);
    for (std::size_t k = 0; k < r.nees.size(); ++k) nees_sum[k] += r.nees[k];
  }
  // When the NEES (2 states) is averaged over the runs at every step after settling
  const double lo = chi2_quantile(2.0 * kRuns, -1.959964) / kRuns;
  const double hi = chi2_quantile(2.0 * kRuns, 1.959964) / kRuns;
  std::size_t inside = 0;
  std::size_t steps = 0;
  double mean = 0.0;
  for (std::size_t k = 20; k < nees_sum.size(); ++k) {
    const double a = nees_sum[k] / kRuns;
    inside += (a >= lo && a <= hi) ? 1 : 0;
    mean += a;
    ++steps;
  }
  mean /= static_cast<double>(steps);
  std::cout << "NEES band [" << lo << ", " << hi << "], mean " << mean << ", inside "
            << static_cast<double>(inside) / static_cast<double>(steps) << "\n";
  // Then about 95 % of the steps are inside the band and the mean is near 2
  EXPECT_GT(static_cast<double>(inside) / static_cast<double>(steps), 0.90);
  EXPECT_GT(mean, lo);
  EXPECT_LT(mean, hi);
}

// ---------------------------------------------------------------- faults (Must show 2)

TEST(HeadingDinghy, FaultFreeRmsBelowPointThreeDegreesWithoutFalseAlarms) {
  const HeadingScenario sc = scenario("dinghy");
  for (int seed = 1; seed <= 5; ++seed) {
    const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(seed));
    const auto r = run(sc, samples, HeadingMethod::kClosedLoop);
    EXPECT_LE(r.rms_deg, 0.3) << "seed " << seed;
    EXPECT_LE(r.exclusions, 1u) << "seed " << seed;  // a false alarm costs little but is counted
    EXPECT_LT(r.mean_nees, 2.0 * 2.0) << "seed " << seed;  // not over-confident in tacks
  }
}

class SingleFault : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(SingleFault, IsolatedWithinTwoSecondsFusedRmsBelowOneDegreeReadmitted) {
  // Given a dinghy beating with 90-degree tacks and one sensor going bad from 60 s to 180 s
  const auto& [name, seed] = GetParam();
  const HeadingScenario sc = scenario(name);
  const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(seed));
  // When closed-loop fusion and plain averaging run on it
  const auto cl = run(sc, samples, HeadingMethod::kClosedLoop);
  const auto avg = run(sc, samples, HeadingMethod::kAverage);
  std::cout << name << " seed " << seed << ": closed-loop RMS " << cl.rms_deg << " max "
            << cl.max_err_deg << "; average RMS " << avg.rms_deg << " max " << avg.max_err_deg
            << "; isolated after " << cl.faults.at(0).isolation_s << " s, re-admitted "
            << cl.faults.at(0).readmit_s << " s after recovery\n";
  // Then the fused heading stays within 1 deg RMS
  EXPECT_LE(cl.rms_deg, 1.0);
  ASSERT_EQ(cl.faults.size(), 1u);
  const auto& f = cl.faults[0];
  // and the sensor is out within 2 s of its error passing 1 deg (silence: of its last reading)
  EXPECT_GE(f.isolation_s, 0.0);
  EXPECT_LE(f.isolation_s, 2.0);
  // and back once healthy, without a jump in the fused heading
  EXPECT_GE(f.readmit_s, 0.0);
  EXPECT_LE(f.readmit_s, 10.0);
  EXPECT_LE(f.readmit_jump_deg, 0.5);
  if (name == "dinghy-spikes") {
    EXPECT_LE(cl.max_err_deg, 2.0);
  }
  // while averaging, which cannot isolate, is off by several degrees (silence does not hurt it)
  if (name != "dinghy-silent") {
    EXPECT_GT(avg.max_err_deg, 3.0);
    EXPECT_GT(avg.rms_deg, 5.0 * cl.rms_deg);
  }
}

INSTANTIATE_TEST_SUITE_P(Seeds, SingleFault,
                         ::testing::Combine(::testing::Values("dinghy-frozen", "dinghy-drift",
                                                              "dinghy-spikes", "dinghy-silent",
                                                              "dinghy-bias"),
                                            ::testing::Values(1, 2, 3)));

TEST(HeadingDinghy, TwoOfThreeFailingKeepsTheSurvivor) {
  // Given sensor 1 silent from 50 s for good and sensor 2 stepping to +4 deg at 80 s
  const HeadingScenario sc = scenario("dinghy-two-fail");
  for (int seed = 1; seed <= 3; ++seed) {
    const auto samples = sim::simulate_heading(sc, static_cast<std::uint64_t>(seed));
    const auto cl = run(sc, samples, HeadingMethod::kClosedLoop);
    const auto avg = run(sc, samples, HeadingMethod::kAverage);
    // Then both are isolated within 2 s, and the lone 5-Hz GNSS compass carries the heading
    ASSERT_EQ(cl.faults.size(), 2u);
    EXPECT_LE(cl.faults[0].isolation_s, 2.0);
    EXPECT_GE(cl.faults[1].isolation_s, 0.0);
    EXPECT_LE(cl.faults[1].isolation_s, 2.0);
    EXPECT_LE(cl.rms_deg, 1.0);
    EXPECT_GT(avg.rms_deg, 3.0 * cl.rms_deg);
  }
}

// ---------------------------------------------------------------- monitor scenarios

TEST(HeadingMonitor, CommonModeStepIsFlaggedAsModelMismatchAndFollowed) {
  // Given three agreeing sensors at 10 deg, then all three at 30 deg at once
  HeadingFusion f(HeadingFusionParams::paper());
  std::array<double, 3> y{10.0, 10.0, 10.0};
  for (int k = 0; k < 50; ++k) f.update(0.1 * k, y.data());
  y = {30.0, 30.05, 29.95};
  f.update(5.0, y.data());
  // Then no sensor agrees with the motion model, the monitor says so and follows the consensus
  EXPECT_TRUE(f.diagnostics().model_mismatch);
  EXPECT_EQ(f.diagnostics().sensors_in_use, 0b111);
  for (int k = 1; k < 30; ++k) f.update(5.0 + 0.1 * k, y.data());
  EXPECT_NEAR(f.heading_deg(), 30.0, 0.2);
  EXPECT_EQ(f.diagnostics().sensors_excluded, 0);
}

TEST(HeadingMonitor, DiagnosticsNameTheReason) {
  HeadingFusionParams p = HeadingFusionParams::paper();
  p.sensor_count = 4;
  HeadingFusion f(p);
  std::array<double, 4> y{};
  for (int k = 0; k < 100; ++k) {
    const double t = 0.1 * k;
    const double h = 100.0 + 2.0 * t;  // turning at 2 deg/s
    y = {h, h, k < 20 ? h : 100.0 + 2.0 * 1.9, k < 50 ? h : kNaN};
    f.update(t, y.data());
  }
  const auto& d = f.diagnostics();
  EXPECT_EQ(d.status[0], HeadingSensorStatus::kInUse);
  EXPECT_TRUE(d.status[2] == HeadingSensorStatus::kInconsistent ||
              d.status[2] == HeadingSensorStatus::kFrozen);  // stuck while the boat turns
  EXPECT_EQ(d.status[3], HeadingSensorStatus::kSilent);
  EXPECT_EQ(d.sensors_in_use, 0b0011);
  EXPECT_EQ(d.sensors_excluded, 0b1100);
  EXPECT_NEAR(f.heading_deg(), 100.0 + 2.0 * 9.9, 0.1);
}

TEST(HeadingMonitor, StuckSensorIsIsolatedOnASlowTurn) {
  // Given three sensors, one stuck, on a boat turning at 0.3 deg/s
  HeadingFusionParams p = HeadingFusionParams::paper();
  p.sensor_count = 3;
  HeadingFusion f(p);
  std::array<double, 3> y{};
  bool frozen_seen = false;
  for (int k = 0; k < 200; ++k) {
    const double t = 0.1 * k;
    const double h = 50.0 + 0.3 * t + 0.05 * std::sin(7.0 * k);  // noise-like wiggle
    y = {h, h + 0.02 * std::cos(5.0 * k),
         k < 30 ? h : 50.0 + 0.3 * 2.9 + 0.05 * std::sin(7.0 * 29)};
    f.update(t, y.data());
    frozen_seen = frozen_seen || f.diagnostics().status[2] == HeadingSensorStatus::kFrozen ||
                  f.diagnostics().status[2] == HeadingSensorStatus::kInconsistent;
  }
  EXPECT_TRUE(frozen_seen);
  EXPECT_FALSE((f.diagnostics().sensors_in_use >> 2) & 1u);
}

TEST(HeadingFusionInput, NonFiniteAndBadTimesAreCountedNeverFused) {
  HeadingFusion f(HeadingFusionParams::paper());
  const double inf = std::numeric_limits<double>::infinity();
  std::array<double, 3> y{10.0, 10.0, 10.0};
  f.update(0.0, y.data());
  y = {inf, 10.0, kNaN};
  f.update(0.1, y.data());
  EXPECT_EQ(f.diagnostics().rejected_non_finite, 1u);
  EXPECT_EQ(f.diagnostics().status[0], HeadingSensorStatus::kNonFinite);
  EXPECT_EQ(f.diagnostics().sensors_in_use, 0b010);
  f.update(0.1, y.data());  // same time
  f.update(kNaN, y.data());
  EXPECT_EQ(f.diagnostics().rejected_time, 2u);
  EXPECT_TRUE(std::isfinite(f.heading_deg()));
  EXPECT_NEAR(f.heading_deg(), 10.0, 1e-6);
}

// ---------------------------------------------------------------- wrap through 360

class WrapInvariance : public ::testing::TestWithParam<HeadingMethod> {};

TEST_P(WrapInvariance, RotatingEveryReadingRotatesTheOutput) {
  // Given the dinghy course (it crosses north at every tack) and the same course turned by c
  const HeadingScenario sc = scenario("dinghy");
  const auto samples = sim::simulate_heading(sc, 3);
  HeadingFusionParams p = sc.fusion;
  p.method = GetParam();
  for (double c : {90.0, 180.0, 359.5, -720.25}) {
    HeadingFusion a(p);
    HeadingFusion b(p);
    double worst = 0.0;
    double worst_step = 0.0;
    double last = kNaN;
    for (const auto& s : samples) {
      std::array<double, 3> yb{};
      for (std::size_t i = 0; i < 3; ++i) yb[i] = s.reading_deg[i] + c;  // any range is accepted
      a.update(s.t_s, s.reading_deg.data());
      b.update(s.t_s, yb.data());
      worst = std::max(worst, std::abs(wrap_180_deg(b.heading_deg() - a.heading_deg() - c)));
      ASSERT_GE(a.heading_deg(), 0.0);
      ASSERT_LT(a.heading_deg(), 360.0);
      if (std::isfinite(last))
        worst_step = std::max(worst_step, std::abs(wrap_180_deg(a.heading_deg() - last)));
      last = a.heading_deg();
    }
    // Then the output turns by c (to rounding) and never jumps by a turn at north
    EXPECT_LT(worst, 1e-6) << "c = " << c;
    EXPECT_LT(worst_step, 6.0);  // 35 deg/s peak tack rate over 0.1 s, plus noise
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, WrapInvariance,
                         ::testing::Values(HeadingMethod::kClosedLoop, HeadingMethod::kCentralized,
                                           HeadingMethod::kDistributed, HeadingMethod::kAverage,
                                           HeadingMethod::kBestSingle));

TEST(HeadingWrap, CircularMeanOfReadingsAcrossNorth) {
  HeadingFusionParams p;
  p.method = HeadingMethod::kAverage;
  HeadingFusion f(p);
  const std::array<double, 3> y{359.0, 1.0, 0.0};
  f.update(0.0, y.data());
  EXPECT_LT(std::abs(wrap_180_deg(f.heading_deg() - 0.0)), 1e-9);
}

TEST(HeadingReadingBuffer, AsynchronousReadingsFlushedPerTickStillIsolateAndTrack) {
  // Given the bias-step dinghy run, sentences received when produced, and a node that flushes at
  // 10 Hz at its own phase, 0..90 ms after the sensors' tick (drifting), so every reading is aged
  const HeadingScenario sc = scenario("dinghy-bias");
  const auto samples = sim::simulate_heading(sc, 4);
  HeadingFusion f(sc.fusion);
  HeadingReadingBuffer buf(3);
  double sq = 0.0;
  int scored = 0;
  bool isolated = false;
  for (const auto& s : samples) {
    for (int i = 0; i < 3; ++i) {
      const double y = s.reading_deg[static_cast<std::size_t>(i)];
      // the sentence describes the heading at s.t_s - latency; it is received a little later
      if (std::isfinite(y)) buf.push(i, s.t_s, y);
    }
    const double phase_s = 0.01 + 0.08 * (0.5 + 0.5 * std::sin(0.05 * s.t_s));
    buf.flush_into(f, s.t_s + phase_s);
    if (s.t_s < sim::kHeadingSettleS) continue;
    // truth at the flush time: first order in the rate
    const double truth = s.truth_heading_deg + phase_s * s.truth_rate_deg_s;
    const double e = wrap_180_deg(f.heading_deg() - truth);
    sq += e * e;
    ++scored;
    if (s.t_s > 62.0 && s.t_s < 180.0)
      isolated = isolated || ((f.diagnostics().sensors_excluded >> 1) & 1u);
  }
  // Then the fused heading stays accurate and the biased sensor is isolated
  EXPECT_LT(std::sqrt(sq / scored), 0.3);
  EXPECT_TRUE(isolated);
  EXPECT_EQ(buf.ignored(), 0u);
  buf.push(7, 1.0, 10.0);
  buf.push(0, 1.0, kNaN);
  EXPECT_EQ(buf.ignored(), 2u);
}

// ---------------------------------------------------------------- N = 8, registry

TEST(HeadingEightSensors, OneBadOfEightIsIsolatedAndTheRestAverageDown) {
  HeadingScenario sc = scenario("dinghy-bias");
  sc.sensors.resize(8, sc.sensors[0]);
  sc.fusion.sensor_count = 8;
  for (std::size_t i = 0; i < 8; ++i) sc.fusion.noise_deg[i] = sc.sensors[i].noise_deg;
  const auto samples = sim::simulate_heading(sc, 11);
  const auto cl = run(sc, samples, HeadingMethod::kClosedLoop);
  const auto three =
      run(scenario("dinghy-bias"), sim::simulate_heading(scenario("dinghy-bias"), 11),
          HeadingMethod::kClosedLoop);
  EXPECT_LE(cl.faults.at(0).isolation_s, 2.0);
  EXPECT_LT(cl.rms_deg, three.rms_deg);
}

TEST(HeadingMethods, RegistryRoundTripsEveryName) {
  for (HeadingMethod m : kAllHeadingMethods) {
    const auto back = heading_method_from_name(heading_method_name(m));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, m);
  }
  EXPECT_FALSE(heading_method_from_name("kalman").has_value());
  EXPECT_EQ(HeadingFusionParams{}.method, HeadingMethod::kClosedLoop);
}

}  // namespace
}  // namespace telltale::fusion
