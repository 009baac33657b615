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
/// The cadence it learns (cadence.hpp: the median of the last measured intervals) is the
/// clock's period.
///
/// Memory: fixed-size arrays, no heap.

#include <optional>

#include "telltale/fusion/pdr/cadence.hpp"
#include "telltale/fusion/pdr/phone_steps.hpp"
#include "telltale/fusion/pdr/recent_samples.hpp"

namespace telltale::fusion {

struct StepClockParams {
  double walk_pause_s = 2.0;  ///< no event for this long: the next is a new walk
  /// After a stand a walk's first event counts only if a second follows within this many step
  /// intervals, without a stand between (the hand's movement made 1-2 lone events). 0: off.
  double walk_start_intervals = 2.0;
  double gap_min_ratio = 1.6;   ///< a gap this many step intervals long has missed steps...
  double gap_max_s = 4.0;       ///< ...if shorter than this...
  double gap_min_energy = 0.5;  ///< ...and the phone's acceleration energy says walking
                                ///< (and it held no stand)
  double min_interval_s = Cadence::kMinIntervalS;  ///< shorter is no cadence
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
