// No heap in the update loops: Eigen's malloc guard around the step detectors and the PDR.
#define EIGEN_RUNTIME_NO_MALLOC
#include <gtest/gtest.h>

#include <Eigen/Core>

#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {
namespace {

TEST(NoHeap, StepDetectorsAndPdrUpdateWithoutEigenAllocation) {
  const auto run =
      sim::simulate_gait(*sim::make_gait_scenario("phone-switch", 4), sim::random_person(4), 4);
  std::vector<std::unique_ptr<StepDetector>> detectors;
  for (auto name : step_detector_names())
    detectors.push_back(make_step_detector(name, StepMount::kBody));
  auto pdr = std::make_unique<Pdr>();
  StepEvent ev;
  std::size_t steps = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  for (const auto& s : run.samples) {
    for (auto& d : detectors) steps += d->update(s.imu, ev) ? 1u : 0u;
    steps += pdr->update(s.imu, s.mag_uT).step ? 1u : 0u;
  }
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_GT(steps, 100u);
}

}  // namespace
}  // namespace telltale::fusion
