// Steps and dead reckoning decide the same whatever a recording's time origin is: the same walk
// stamped from 0 (a file, the simulator) or with Unix time (a phone, gpsd, the wearable's live
// clock) gives the same steps at the same times. A sensor's clock ticks on a grid (t0 + n / rate),
// so durations between samples land exactly on a detector's thresholds (0.2 s at 100 Hz is 20
// samples; 0.99 s is 1.5 x 0.66 s): compared as doubles, the side they fall on depends on how the
// time stamps round, and so on t0. Seen failing before the detectors ran on a LocalClock
// (imu_sample.hpp): 574 step times one sample apart, 179 hand-held steps and 10 counts here; on
// the shared IPOL lower-back trials, stamped with Unix time, the hand-held PDR counted 23 -> 29
// steps on one file and changed its count on four more, the `peak` and `peak-valley` foot
// detectors on one and three files.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "oxford_traces.hpp"
#include "telltale/fusion/foot_pdr.hpp"
#include "telltale/fusion/handheld_pdr.hpp"
#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/sim/phone_walk.hpp"
#include "telltale/fusion/steps.hpp"
#include "telltale/fusion/trunk_pdr.hpp"

namespace telltale::fusion {
namespace {

/// 2024-12-05 11:20 UTC and a fraction: a Unix time as a phone or gpsd stamps it.
constexpr double kUnixOffset_s = 1733397600.123;

std::vector<ImuSample> shifted(std::vector<ImuSample> samples, double offset_s) {
  for (auto& s : samples) s.t_s += offset_s;
  return samples;
}

/// Step times of a detector, less `offset_s`.
std::vector<double> step_times(std::string_view name, StepMount mount,
                               const std::vector<ImuSample>& samples, double offset_s) {
  auto d = make_step_detector(name, mount);
  std::vector<double> t;
  for_each_step(*d, shifted(samples, offset_s),
                [&](const StepEvent& ev) { t.push_back(ev.t_s - offset_s); });
  return t;
}

void expect_same(const std::vector<double>& a, const std::vector<double>& b,
                 const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-5) << what << " step " << i;
}

std::vector<ImuSample> gait_samples(const std::string& scenario, std::uint64_t seed) {
  const auto run =
      sim::simulate_gait(*sim::make_gait_scenario(scenario, seed), sim::random_person(seed), seed);
  std::vector<ImuSample> out;
  for (const auto& s : run.samples) out.push_back(s.imu);
  return out;
}

// Given every step detector on simulated walks of both mounts, when the time stamps move to
// Unix time, then the steps are the same, at the same times.
TEST(TimeOrigin, StepDetectorsOnSimulatedWalks) {
  for (const std::string site : {"foot", "body"}) {
    const auto mount = site == "foot" ? StepMount::kFoot : StepMount::kBody;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const auto samples = gait_samples(site + "-mixed", seed);
      for (auto name : step_detector_names())
        expect_same(step_times(name, mount, samples, 0.0),
                    step_times(name, mount, samples, kUnixOffset_s),
                    std::string(name) + " " + site + " seed " + std::to_string(seed));
    }
  }
}

// The same on the real Oxford phone traces (tests/data/oxford_steps, CC BY 4.0): accelerometer
// only, 50 Hz, every detector.
TEST(TimeOrigin, StepDetectorsOnRealPhoneTraces) {
  const auto traces = read_oxford_traces();
  ASSERT_EQ(traces.size(), 24u);
  for (const auto& trace : traces)
    for (auto name : step_detector_names())
      expect_same(step_times(name, StepMount::kBody, trace.samples, 0.0),
                  step_times(name, StepMount::kBody, trace.samples, kUnixOffset_s),
                  std::string(name) + " " + trace.name);
}

// Given the hand-held PDR on simulated IPIN-like walks (handling, standing, a loop with
// pauses), when the time stamps move to Unix time, then it lays the same steps at the same
// places.
TEST(TimeOrigin, HandheldPdrOnSimulatedPhoneWalks) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    sim::PhoneWalkParams p;
    const auto w = sim::simulate_phone_walk(sim::ipin_like_plan(seed, 1.75, p), p, seed);
    std::vector<HandheldStep> steps[2];
    for (int k = 0; k < 2; ++k) {
      HandheldPdr pdr;
      const double offset = k == 0 ? 0.0 : kUnixOffset_s;
      for (std::size_t i = 0; i < w.samples.size(); ++i) {
        ImuSample s = w.samples[i];
        s.t_s += offset;
        const int n = pdr.update(s, w.mag_uT[i]);
        for (int j = 0; j < n; ++j) steps[k].push_back(pdr.steps()[static_cast<std::size_t>(j)]);
      }
    }
    ASSERT_GT(steps[0].size(), 50u) << "seed " << seed;
    ASSERT_EQ(steps[0].size(), steps[1].size()) << "seed " << seed;
    for (std::size_t i = 0; i < steps[0].size(); ++i) {
      EXPECT_NEAR(steps[0][i].t_s, steps[1][i].t_s - kUnixOffset_s, 1e-5) << seed << " " << i;
      EXPECT_NEAR(steps[0][i].x_m, steps[1][i].x_m, 1e-3) << seed << " " << i;
      EXPECT_NEAR(steps[0][i].y_m, steps[1][i].y_m, 1e-3) << seed << " " << i;
    }
  }
}

// The foot's, the trunk's and the four-pose PDR's step counts and distances, the same way.
TEST(TimeOrigin, FootTrunkAndPosePdr) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (const std::string scenario : {"foot-mixed", "body-mixed", "loop"}) {
      const auto run = sim::simulate_gait(*sim::make_gait_scenario(scenario, seed),
                                          sim::random_person(seed), seed);
      PdrOutput out[2];
      for (int k = 0; k < 2; ++k) {
        FootPdr foot;
        auto trunk = std::make_unique<TrunkPdr>();
        Pdr pose;
        const double offset = k == 0 ? 0.0 : kUnixOffset_s;
        for (const auto& g : run.samples) {
          ImuSample s = g.imu;
          s.t_s += offset;
          out[k] = scenario == "loop"         ? pose.update(s, g.mag_uT)
                   : scenario == "body-mixed" ? trunk->update(s, g.mag_uT)
                                              : foot.update(s, g.mag_uT);
        }
      }
      EXPECT_EQ(out[0].steps, out[1].steps) << scenario << " seed " << seed;
      EXPECT_NEAR(out[0].distance_m, out[1].distance_m, 1e-3) << scenario << " seed " << seed;
    }
  }
}

}  // namespace
}  // namespace telltale::fusion
