#pragma once
/// \file
/// PDR stage: the cadence and the steps a detector left in a gap (our addition). Owns the step
/// interval (the median of the last measured ones), the last step's time and the heading over
/// the last seconds, because a gap is measured in step intervals and its steps are laid along
/// the heading each part of it had. The foot pipeline (FootPdr) uses the cadence only: its
/// detector sees every stride, so it fills no gap (learn_cadence).
///
/// Memory: fixed-size arrays, no heap.

#include <array>
#include <cstddef>
#include <cstdint>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/phone_steps.hpp"
#include "telltale/fusion/pdr/recent_samples.hpp"

namespace telltale::fusion {

struct StepGapParams {
  double min_ratio = 1.6;       ///< a gap this many step intervals long has missed steps...
  double max_gap_s = 4.0;       ///< ...if shorter than this...
  double min_energy = 0.5;      ///< ...and the phone's acceleration energy says walking
                                ///< (and it held no stand: StepSource::after_stand)
  double min_interval_s = 0.2;  ///< 5 steps/s, a sprinter's: shorter is no cadence
};

class StepGaps {
 public:
  using Params = StepGapParams;
  explicit StepGaps(Params params);
  /// Per sample: the heading filter's heading as (cos, sin).
  void add_heading(double t_s, const Eigen::Vector2d& unit);
  /// The walking frame changed at t_s: the headings before are in another frame.
  void new_frame(double t_s) { bins_from_t_s_ = t_s; }
  /// A step event of the phone at t_s: returns how many more steps the gap before it held
  /// (`energy` the phone's acceleration energy over the feature window) and learns the cadence
  /// from it.
  int at_step(double t_s, const StepSource& source, double energy, const RecentSamples& recent);
  /// An event at t_s that stands for `per_event` steps (a foot sensor's stride: 2) and whose
  /// gap is never filled: learns the cadence only.
  void learn_cadence(double t_s, double per_event);
  /// For a gap [t0, t1] walked in `parts` equal steps: the mean of the unit vectors of each
  /// part's heading relative to the whole gap's (x along, y clockwise); (1, 0) when the
  /// headings kept do not cover the gap.
  [[nodiscard]] Eigen::Vector2d gap_turn(double t0_s, double t1_s, int parts) const;
  /// The step interval, s (0 until one is measured).
  [[nodiscard]] double interval_s() const { return interval_s_; }
  /// The last step event's time (< 0: none yet).
  [[nodiscard]] double last_step_t_s() const { return last_step_t_s_; }

 private:
  /// The event at t_s ends the gap since the last; with `learn`, its interval per step
  /// (`per_event` steps in it) is a cadence measurement.
  void end_gap(double t_s, double per_event, bool learn);
  void learn_interval(double interval_s);
  Params params_;
  double last_step_t_s_ = -1.0;
  /// The step interval: the median of the last kIntervals measured ones (0 until one is).
  double interval_s_ = 0.0;
  static constexpr std::size_t kIntervals = 5;
  std::array<double, kIntervals> intervals_{};
  std::size_t interval_count_ = 0;
  int filled_row_ = 0;  ///< steps in a row that filled a gap
  /// The heading over the last seconds, in 0.1 s bins (sums of unit vectors, since the walking
  /// frame last changed).
  static constexpr std::size_t kHeadingBins = 64;
  static constexpr double kHeadingBinS = 0.1;
  std::array<Eigen::Vector2d, kHeadingBins> bins_{};
  std::array<std::int64_t, kHeadingBins> bin_id_{};
  double bins_from_t_s_ = 0.0;
};

}  // namespace telltale::fusion
