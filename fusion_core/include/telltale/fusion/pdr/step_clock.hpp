#pragma once
/// \file
/// PDR stage (phone pipeline): the step clock. The phone has two step detectors (PhoneSteps:
/// the acceleration's peaks and valleys, the arm's turns while the phone swings), and every
/// event of either is read against one clock, the walk's last step and its cadence, which alone
/// decides how many steps the event stands for:
///   - none: the other detector's mark of a step already counted (a handoff), or a walk's first
///     event after a stand, held until a second confirms it;
///   - one: a step;
///   - one and n before it: the held first event of a walk, now confirmed; the arm's turns of a
///     walk that began swinging before the swing was recognised; the steps in a gap of about
///     n + 1 intervals while the phone kept moving like a walk.
/// The cadence it learns (Cadence: the median of the last measured intervals) is the clock's
/// period. The foot pipeline (FootPdr) keeps a Cadence alone: its detector sees every stride.
///
/// Memory: fixed-size arrays, no heap.

#include <array>
#include <cstddef>
#include <optional>

#include "telltale/fusion/pdr/recent_samples.hpp"

namespace telltale::fusion {

/// The step interval: the median of the last measured ones, and the last step's time.
class Cadence {
 public:
  /// Shorter intervals are no cadence (5 steps/s is a sprinter's).
  explicit Cadence(double min_interval_s = 0.2) : min_interval_s_(min_interval_s) {}
  /// A step event at t_s standing for `per_event` steps (a foot's stride: 2). With `learn`, the
  /// interval since the last, per step, is a cadence measurement; either way t_s is the last
  /// step's time from now on.
  void at_step(double t_s, double per_event, bool learn);
  /// The cadence is unknown again (the last step's time is kept).
  void forget();
  /// The step interval, s (0 until one is measured).
  [[nodiscard]] double interval_s() const { return interval_s_; }
  /// The last step's time (< 0: none yet).
  [[nodiscard]] double last_step_t_s() const { return last_step_t_s_; }

 private:
  void learn_interval(double interval_s);
  double min_interval_s_;
  double last_step_t_s_ = -1.0;
  double interval_s_ = 0.0;
  static constexpr std::size_t kIntervals = 5;
  std::array<double, kIntervals> intervals_{};
  std::size_t interval_count_ = 0;
};

struct StepClockParams {
  double walk_pause_s = 2.0;  ///< no event for this long: the next is a new walk
  /// After a stand a walk's first event counts only if a second follows within this many step
  /// intervals, without a stand between (the hand's movement made 1-2 lone events). 0: off.
  double walk_start_intervals = 2.0;
  double gap_min_ratio = 1.6;   ///< a gap this many step intervals long has missed steps...
  double gap_max_s = 4.0;       ///< ...if shorter than this...
  double gap_min_energy = 0.5;  ///< ...and the phone's acceleration energy says walking
                                ///< (and it held no stand)
  double min_interval_s = 0.2;  ///< 5 steps/s, a sprinter's: shorter is no cadence
};

/// What the phone's two detectors saw at one sample (PhoneSteps::update).
struct PhoneEvents {
  double t_s = 0.0;       ///< the sample's time
  bool by_acc = false;    ///< the acceleration's peak and valley closed a step
  bool by_swing = false;  ///< the arm turned
  /// The phone swings (gyro present): the arm's turns speak for the steps, else the
  /// acceleration does.
  bool swing = false;
  double swing_step_t_s = 0.0;  ///< the arm's last turn's step time
  double half_swing_s = 0.0;    ///< the arm's recent half swing, s
  [[nodiscard]] bool any() const { return by_acc || by_swing; }
};

/// A step the clock counts.
struct ClockStep {
  double t_s = 0.0;        ///< when it happened
  double prev_t_s = -1.0;  ///< the step before it (< 0: none)
  /// Steps before it counted with it: a gap's, a held start's, a swinging start's.
  int extra = 0;
};

class StepClock {
 public:
  using Params = StepClockParams;
  explicit StepClock(Params params) : params_(params), cadence_(params.min_interval_s) {}
  /// The detectors' events at one sample; `recent` tells a stand and a walk's rhythm, `energy`
  /// is the phone's acceleration energy over the pose window (read only when events.any()).
  /// A step if the events stand for one.
  std::optional<ClockStep> at_events(const PhoneEvents& events, const RecentSamples& recent,
                                     double energy);
  [[nodiscard]] const Cadence& cadence() const { return cadence_; }

 private:
  /// Steps the gap before a step at t_s held; learns the cadence from it unless `no_cadence`.
  int fill_gap(double t_s, bool after_stand, bool no_cadence, double energy,
               const RecentSamples& recent);
  Params params_;
  Cadence cadence_;
  bool last_step_by_swing_ = false;
  struct Walk {  ///< since the last pause
    double last_event_t_s = -1e9;
    int swing_events = 0;  ///< the arm's turns
    int steps = 0;         ///< steps counted (either detector)
    bool backfilled = false;
  } walk_;
  double start_pending_t_s_ = -1.0;  ///< a walk's first event after a stand, held
  int filled_row_ = 0;               ///< steps in a row that filled a gap
};

}  // namespace telltale::fusion
