#pragma once
/// \file
/// PDR stage: the cadence, the step clock's period (step_clock.hpp). The foot pipeline (FootPdr)
/// keeps one alone: its detector sees every stride, so it has no gap to fill.
///
/// Memory: a fixed-size array, no heap.

#include <array>
#include <cstddef>

namespace telltale::fusion {

/// The step interval: the median of the last measured ones, and the last step's time.
class Cadence {
 public:
  /// Shorter intervals are no cadence: 5 steps/s is a sprinter's.
  static constexpr double kMinIntervalS = 0.2;
  explicit Cadence(double min_interval_s = kMinIntervalS) : min_interval_s_(min_interval_s) {}
  /// A step event at t_s standing for `per_event` steps (a foot's stride: 2). With `learn`, the
  /// interval since the last, per step, is a cadence measurement; either way t_s is the last
  /// step's time from now on.
  void at_step(double t_s, double per_event, bool learn);
  /// The cadence is unknown again (the last step's time is kept).
  void forget();
  /// The step interval, s: 0 until kMinIntervals have been measured. One interval is one
  /// measurement, not a cadence: a walk's first two events may be one step detected twice
  /// (0.2 s apart, read as 300 steps/min), and everything that trusts the cadence goes wrong
  /// with it (the body PDR laid every step of a lower-back walk twice at 1.9 m each, ten steps
  /// in a row, before the gap filler gave up on it). The median of three outvotes one.
  [[nodiscard]] double interval_s() const {
    return interval_count_ >= kMinIntervals ? interval_s_ : 0.0;
  }
  /// The last step's time (< 0: none yet).
  [[nodiscard]] double last_step_t_s() const { return last_step_t_s_; }

 private:
  void learn_interval(double interval_s);
  double min_interval_s_;
  double last_step_t_s_ = -1.0;
  double interval_s_ = 0.0;
  static constexpr std::size_t kIntervals = 5;
  static constexpr std::size_t kMinIntervals = 3;
  std::array<double, kIntervals> intervals_{};
  std::size_t interval_count_ = 0;
};

}  // namespace telltale::fusion
