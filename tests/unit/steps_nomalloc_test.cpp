// No heap in the update loops of the step detectors and the PDRs (STYLE 5), with the shared
// counting allocator of no_heap_guard.hpp.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "no_heap_guard.hpp"
#include "telltale/fusion/foot_pdr.hpp"
#include "telltale/fusion/handheld_pdr.hpp"
#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/steps.hpp"
#include "telltale/fusion/trunk_pdr.hpp"

namespace telltale::fusion {
namespace {

using telltale::test::allocations_in;

TEST(NoHeap, StepDetectorsAndPdrUpdateWithoutAllocation) {
  for (const char* scenario : {"phone-switch", "foot-mixed"}) {
    const auto run =
        sim::simulate_gait(*sim::make_gait_scenario(scenario, 4), sim::random_person(4), 4);
    const auto mount =
        std::string(scenario).rfind("foot", 0) == 0 ? StepMount::kFoot : StepMount::kBody;
    std::vector<std::unique_ptr<StepDetector>> detectors;
    for (auto name : step_detector_names()) detectors.push_back(make_step_detector(name, mount));
    auto pdr = std::make_unique<Pdr>();
    auto foot_pdr = std::make_unique<FootPdr>();
    auto handheld = std::make_unique<HandheldPdr>();
    auto trunk = std::make_unique<TrunkPdr>();
    StepEvent ev;
    std::size_t steps = 0, handheld_steps = 0, foot_steps = 0, trunk_steps = 0;
    const std::size_t n = allocations_in([&] {
      for (const auto& s : run.samples) {
        for (auto& d : detectors) steps += d->update(s.imu, ev) ? 1u : 0u;
        steps += pdr->update(s.imu, s.mag_uT).step ? 1u : 0u;
        foot_steps += foot_pdr->update(s.imu, s.mag_uT).step ? 1u : 0u;
        trunk_steps += trunk->update(s.imu, s.mag_uT).step ? 1u : 0u;
        handheld_steps += static_cast<std::size_t>(handheld->update(s.imu, s.mag_uT));
      }
    });
    EXPECT_EQ(n, 0u) << scenario << ": heap allocations in the update loops";
    EXPECT_GT(steps, 100u) << scenario;
    // Every pipeline runs on both scenarios (no heap whatever the sensor says); steps are
    // checked where the sensor is: the phone scenario walks with the phone held in front part
    // of the time, the foot scenario's strides are FootPdr's.
    if (mount == StepMount::kBody) {
      EXPECT_GT(handheld_steps, 20u) << scenario;
      EXPECT_GT(trunk_steps, 20u) << scenario;
    } else {
      EXPECT_GT(foot_steps, 100u) << scenario;
    }
  }
}

}  // namespace
}  // namespace telltale::fusion
