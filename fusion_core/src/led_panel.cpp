#include "telltale/fusion/led_panel.hpp"

#include <algorithm>
#include <cmath>

namespace telltale::fusion {
namespace {
std::uint8_t leds_for(double magnitude_deg, const LedPanelParams& p) {
  if (!(magnitude_deg >= 0.0) || !(p.step_deg > 0.0)) return 0;  // NaN or a broken setting
  const double n = std::floor(magnitude_deg / p.step_deg);
  return static_cast<std::uint8_t>(std::min(n, static_cast<double>(p.leds_per_bar)));
}
}  // namespace

LedPanelState led_panel(double heel_deg, double pitch_deg, const LedPanelParams& params) {
  LedPanelState s;
  if (heel_deg < 0.0) s.left = leds_for(-heel_deg, params);
  if (heel_deg > 0.0) s.right = leds_for(heel_deg, params);
  if (pitch_deg > 0.0) s.up = leds_for(pitch_deg, params);
  if (pitch_deg < 0.0) s.down = leds_for(-pitch_deg, params);
  return s;
}

}  // namespace telltale::fusion
