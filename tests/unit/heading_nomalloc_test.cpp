// No heap in HeadingFusion::update / HeadingReadingBuffer::flush_into, for every method.
//
// This executable compiles the heading sources itself with EIGEN_RUNTIME_NO_MALLOC for the whole
// target (tests/CMakeLists.txt), and without NDEBUG: defining the macro in the test file alone
// would leave the library's own Eigen code unchecked, and with NDEBUG the guard (an eigen_assert)
// checks nothing. The death test proves the guard is live.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>

#include "telltale/fusion/heading_fusion.hpp"

#if !defined(EIGEN_RUNTIME_NO_MALLOC) || defined(NDEBUG)
#error "build this test with EIGEN_RUNTIME_NO_MALLOC and without NDEBUG for the whole target"
#endif

namespace telltale::fusion {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(HeadingNoHeapDeathTest, TheGuardIsLive) {
  EXPECT_DEATH(
      {
        Eigen::internal::set_is_malloc_allowed(false);
        Eigen::MatrixXd m(16, 16);
        m.setZero();
      },
      "");
}

TEST(HeadingNoHeap, UpdateNeverAllocatesForAnyMethodWithThreeOrEightSensors) {
  for (int n : {3, 8}) {
    for (HeadingMethod m : kAllHeadingMethods) {
      HeadingFusionParams p;
      p.sensor_count = n;
      p.method = m;
      HeadingFusion f(p);
      std::array<double, kMaxHeadingSensors> y{};
      Eigen::internal::set_is_malloc_allowed(false);
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
      HeadingReadingBuffer buf(n);
      for (int k = 0; k < 50; ++k) {
        buf.push(k % n, 40.0 + 0.1 * k, 123.0);
        buf.flush_into(f, 40.0 + 0.1 * k + 0.01);
      }
      Eigen::internal::set_is_malloc_allowed(true);
      EXPECT_TRUE(std::isfinite(f.heading_deg())) << heading_method_name(m);
    }
  }
}

}  // namespace
}  // namespace telltale::fusion
