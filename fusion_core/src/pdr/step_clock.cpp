#include "telltale/fusion/pdr/step_clock.hpp"

#include <algorithm>
#include <cmath>

namespace telltale::fusion {

std::optional<ClockStep> StepClock::at_events(const PhoneEvents& e, const RecentSamples& recent,
                                              double energy) {
  if (!e.any()) return std::nullopt;
  if (e.t_s - walk_.last_event_t_s > params_.walk_pause_s) walk_ = {};  // a new walk
  walk_.last_event_t_s = e.t_s;
  walk_.swing_events += e.by_swing ? 1 : 0;
  if (!(e.swing ? e.by_swing : e.by_acc)) return std::nullopt;  // the other detector speaks
  const double last = cadence_.last_step_t_s();
  const double interval = cadence_.interval_s();
  // A handoff: the arm turns at a heel strike, the acceleration's valley closes a step just
  // after one, so when one detector takes over from the other, an event less than half an
  // interval after the last step is that same step. Across a handoff the two detectors mark a
  // step at different moments of it (the valley 0.0-0.4 s after the strike, the arm's turn
  // ~0.05 s): the interval is no cadence.
  const bool handoff = e.swing != last_step_by_swing_;
  if (handoff && last >= 0.0 && e.t_s - last < 0.5 * std::max(interval, e.half_swing_s))
    return std::nullopt;
  bool no_cadence = handoff;
  const bool after_stand = last >= 0.0 && recent.quiet_between(last, e.t_s);
  int extra = 0;
  // A walk after a stand (the phone still since the last step) begins with its first event
  // held until a second follows within walk_start_intervals with no stand between: a hand
  // moving the phone (putting it away, lifting it to the ear) makes one event, or two far apart.
  if (params_.walk_start_intervals > 0.0 && interval > 0.0 && after_stand) {
    const bool confirmed = start_pending_t_s_ >= 0.0 &&
                           e.t_s - start_pending_t_s_ < params_.walk_start_intervals * interval &&
                           !recent.quiet_between(start_pending_t_s_, e.t_s);
    if (!confirmed) {
      start_pending_t_s_ = e.t_s;
      return std::nullopt;
    }
    start_pending_t_s_ = -1.0;
    ++extra;            // the held event
    ++walk_.steps;      // (a swinging start's count below must know it was counted)
    no_cadence = true;  // and no cadence across the stand
  }
  last_step_by_swing_ = e.swing;
  // A walk that starts swinging: the swing is recognised after two half swings, and the
  // acceleration may have missed the steps before (the pendulum lifts every valley above the
  // standing mean). The arm's turns since the walk began say how many: they are counted with
  // this step, if the walk is that young (its first kBackfillEvents turns).
  constexpr int kBackfillEvents = 8;
  if (e.swing && !walk_.backfilled && walk_.swing_events <= kBackfillEvents)
    extra += std::max(0, walk_.swing_events - walk_.steps - 1);
  if (e.swing) walk_.backfilled = true;
  ++walk_.steps;
  ClockStep step;
  step.t_s = e.swing ? e.swing_step_t_s : e.t_s;
  step.prev_t_s = last;
  step.extra = extra + fill_gap(step.t_s, after_stand, no_cadence, energy, recent);
  return step;
}

int StepClock::fill_gap(double t_s, bool after_stand, bool no_cadence, double energy,
                        const RecentSamples& recent) {
  // Steps the detector missed: its thresholds follow the last steps' peaks and valleys, so after
  // an arm swing the smaller steps of the next pose go unseen until its memory resets (4-9
  // steps lost per arm-swing exit, measured; not always while a switch is detected). A gap of
  // about n step intervals while the phone kept moving like a walk (acceleration energy over
  // the last window) counts n - 1 more steps; a stop does not.
  int missed = 0;
  const double last = cadence_.last_step_t_s();
  const double interval = cadence_.interval_s();
  if (last >= 0.0 && interval > 0.0) {
    const double gap = t_s - last;
    const double ratio = gap / interval;
    if (ratio > params_.gap_min_ratio && gap < params_.gap_max_s &&
        energy > params_.gap_min_energy && !after_stand)
      missed = static_cast<int>(std::lround(ratio)) - 1;
  }
  // Filling in needs a cadence that was measured. A gap after every step is no missed step but a
  // cadence that is wrong (learnt from two detections of one step, or from a detector that has
  // since locked onto the stride): after kMaxFilledRow filled steps in a row the cadence is
  // learnt again from the gaps. (Learning it from the gaps divided by the steps filled into
  // them kept any wrong cadence for ever: 2 or 8 steps counted for every one.)
  constexpr int kMaxFilledRow = 10;
  filled_row_ = missed > 0 ? filled_row_ + 1 : 0;
  if (filled_row_ > kMaxFilledRow && !recent.walking_period(interval)) {
    missed = 0;
    filled_row_ = 0;
    cadence_.forget();
  }
  cadence_.at_step(t_s, 1.0, missed == 0 && !no_cadence);
  return missed;
}

}  // namespace telltale::fusion
