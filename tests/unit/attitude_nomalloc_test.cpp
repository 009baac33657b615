// No heap inside update(), for every attitude filter, with the shared counting allocator of
// no_heap_guard.hpp (fusion_core linked as built for the product).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "no_heap_guard.hpp"
#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/attitude_telltale.hpp"

namespace telltale::fusion {
namespace {

TEST(AttitudeNoHeap, UpdateAllocatesNothing) {
  // Samples prepared before the guard: a roll, a knock, a NaN, a gap and a saturated gyro.
  std::vector<ImuSample> samples;
  for (int k = 0; k < 2000; ++k) {
    const double t = 0.01 * k + (k > 1500 ? 2.0 : 0.0);
    const double h = 0.3 * std::sin(0.5 * t);
    ImuSample s{t,
                {0.15 * std::cos(0.5 * t), 0.02, 0.1},
                {0.1, telltale::fusion::kStandardGravity_m_s2 * std::sin(h),
                 telltale::fusion::kStandardGravity_m_s2 * std::cos(h)}};
    if (k == 700) s.acc_body_m_s2 = {20.0, -20.0, 20.0};
    if (k == 900) s.gyro_body_rad_s.x() = std::nan("");
    if (k == 1100) s.gyro_body_rad_s = {5.0, 5.0, 5.0};
    samples.push_back(s);
  }
  std::vector<std::pair<std::string, std::unique_ptr<AttitudeFilter>>> filters;
  for (const auto& name : attitude_filter_names())
    filters.emplace_back(name, make_attitude_filter(name));
  // The production filter as a boat's node runs it, with its sensor off the centre (the lever
  // arm's path in the update).
  TelltaleAttitudeParams on_the_bow;
  on_the_bow.lever_arm_m = {1.5, 0.0, 0.25};
  filters.emplace_back("telltale, sensor offset",
                       std::make_unique<TelltaleAttitudeFilter>(on_the_bow));
  for (auto& [name, filter] : filters) {
    double sink = 0.0;
    const std::size_t n = telltale::test::allocations_in([&] {
      for (std::size_t k = 0; k < samples.size(); ++k) {
        const ImuSample& s = samples[k];
        // The boat's speed from GNSS for the first half (held from 5 Hz fixes), unknown after.
        if (k % 20 == 0) filter->set_speed(k < 1000 ? 2.5 : std::nan(""), 0.1, 0.05);
        filter->update(s);
        sink += filter->output().heel_rad;
      }
    });
    EXPECT_EQ(n, 0u) << name;
    EXPECT_TRUE(std::isfinite(sink)) << name;
  }
}

}  // namespace
}  // namespace telltale::fusion
