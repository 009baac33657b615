#pragma once
/// \file
/// The instrument's LED warning panel (SPEC section 2, paper 000 section 4): one LED per 5 degrees
/// on each bar. Heel < 0 (port down) lights the left bar, heel > 0 the right bar; pitch > 0 (bow
/// up) lights the up bar, pitch < 0 the down bar. The paper's example: heel in [-20,-15] -> 3 left
/// LEDs; pitch in [5,10] -> 1 up LED. So the count is floor(|angle| / step), capped at the bar.

#include <cstdint>

namespace telltale::fusion {

struct LedPanelParams {
  double step_deg = 5.0;    ///< degrees per LED
  std::uint8_t leds_per_bar = 6;
};

struct LedPanelState {
  std::uint8_t left = 0;
  std::uint8_t right = 0;
  std::uint8_t up = 0;
  std::uint8_t down = 0;
};

/// LEDs lit for the given heel and pitch (degrees). NaN lights nothing.
[[nodiscard]] LedPanelState led_panel(double heel_deg, double pitch_deg,
                                      const LedPanelParams& params = {});

}  // namespace telltale::fusion
