#include "telltale/fusion/led_panel.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace telltale::fusion {
namespace {

// The paper's example: heel in [-20,-15] lights 3 left LEDs; pitch in [5,10] lights 1 up LED.
TEST(LedPanel, PaperExample) {
  for (double heel : {-15.0, -17.5, -19.99}) {
    for (double pitch : {5.0, 7.5, 9.99}) {
      const auto s = led_panel(heel, pitch);
      EXPECT_EQ(s.left, 3);
      EXPECT_EQ(s.right, 0);
      EXPECT_EQ(s.up, 1);
      EXPECT_EQ(s.down, 0);
    }
  }
}

TEST(LedPanel, OneLedPerFiveDegreesCappedAtTheBar) {
  EXPECT_EQ(led_panel(4.99, 0).right, 0);
  EXPECT_EQ(led_panel(5.0, 0).right, 1);
  EXPECT_EQ(led_panel(29.9, 0).right, 5);
  EXPECT_EQ(led_panel(80.0, 0).right, 6);
  EXPECT_EQ(led_panel(0, -12.0).down, 2);
  EXPECT_EQ(led_panel(0, -12.0, {.step_deg = 3.0, .leds_per_bar = 8}).down, 4);
  const auto s = led_panel(std::nan(""), std::nan(""));
  EXPECT_EQ(s.left + s.right + s.up + s.down, 0);
}

}  // namespace
}  // namespace telltale::fusion
