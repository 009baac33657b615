#pragma once
/// \file
/// The instrument's LED panel on the node's console, and the warning hook (a command run when
/// the boat's alarm level rises, e.g. to sound a buzzer).

#include <chrono>
#include <cstdio>
#include <string>

#include "telltale/fusion/alarm_engine.hpp"
#include "telltale/fusion/led_panel.hpp"

namespace telltale::boat {

/// One line of the panel: left bar, heel, right bar | up bar, pitch, down bar, level. ANSI
/// colours when `colour` (a terminal), plain characters otherwise. Lit LEDs are '#', dark '.'.
[[nodiscard]] std::string render_panel(const std::string& boat_id, double heel_deg,
                                       double pitch_deg, const fusion::LedPanelState& leds,
                                       int leds_per_bar, fusion::AlarmLevel level, bool colour);

/// Runs `command` through /bin/sh when the level rises to warn or alarm (not more often than
/// every `min_interval`), with TELLTALE_BOAT, TELLTALE_LEVEL and TELLTALE_VALUE_DEG in its
/// environment. Never blocks: children are reaped on later calls.
class WarningHook {
 public:
  WarningHook(std::string command, std::chrono::seconds min_interval)
      : command_(std::move(command)), min_interval_(min_interval) {}
  ~WarningHook();
  void on_level(const std::string& boat_id, fusion::AlarmLevel level, double value_deg,
                std::chrono::steady_clock::time_point now);
  [[nodiscard]] unsigned runs() const { return runs_; }

 private:
  std::string command_;
  std::chrono::seconds min_interval_;
  fusion::AlarmLevel last_ = fusion::AlarmLevel::kNormal;
  std::chrono::steady_clock::time_point last_run_{};
  unsigned runs_ = 0;
};

}  // namespace telltale::boat
