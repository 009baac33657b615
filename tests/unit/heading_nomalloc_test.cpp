// No heap in HeadingFusion::update / HeadingReadingBuffer::flush_into, for every method, with
// the shared counting allocator of no_heap_guard.hpp (fusion_core linked as built).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "no_heap_guard.hpp"
#include "telltale/fusion/heading_fusion.hpp"

namespace telltale::fusion {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(HeadingNoHeap, UpdateNeverAllocatesForAnyMethodWithThreeOrEightSensors) {
  for (int n : {3, 8}) {
    for (HeadingMethod m : kAllHeadingMethods) {
      HeadingFusionParams p;
      p.sensor_count = n;
      p.method = m;
      HeadingFusion f(p);
      std::array<double, kMaxHeadingSensors> y{};
      const std::size_t heap_update = telltale::test::allocations_in([&] {
        for (int k = 0; k < 400; ++k) {
          for (int i = 0; i < n; ++i) {
            // readings, gaps, a stuck and a spiking sensor: every branch of the monitor runs
            const double h = 350.0 + 20.0 * std::sin(0.05 * k) + 0.1 * std::sin(13.0 * (k + i));
            y[static_cast<std::size_t>(i)] = (i == 1 && k > 100)       ? 7.0
                                             : (i == 2 && k % 7 == 0)  ? kNaN
                                             : (i == 0 && k % 50 == 0) ? h + 25.0
                                                                       : h;
          }
          f.update(0.1 * k, y.data());
        }
      });
      EXPECT_EQ(heap_update, 0u) << heading_method_name(m);
      HeadingReadingBuffer buf(n);
      const std::size_t heap = telltale::test::allocations_in([&] {
        for (int k = 0; k < 50; ++k) {
          buf.push(k % n, 40.0 + 0.1 * k, 123.0);
          buf.flush_into(f, 40.0 + 0.1 * k + 0.01);
        }
      });
      EXPECT_EQ(heap, 0u) << heading_method_name(m);
      EXPECT_TRUE(std::isfinite(f.heading_deg())) << heading_method_name(m);
    }
  }
}

}  // namespace
}  // namespace telltale::fusion
