#include "telltale/fusion/pdr/phone_steps.hpp"

#include <algorithm>

namespace telltale::fusion {

bool PhoneSteps::update(const ImuSample& s, const Eigen::Vector3d& up, double last_step_t_s,
                        double interval_s, const RecentSamples& recent, StepEvent& ev,
                        StepSource& source) {
  const bool by_acc = acc_steps_.update(s, ev);
  // While the phone swings (a swinging arm; a thigh, for a phone in a trouser pocket) its turns
  // count the steps (SwingStepDetector), whatever the pose: in arm swing the hand's pendulum
  // swamps the trunk's acceleration and the peak-valley detector loses steps, or the whole
  // walk at a slow pace (and with it the pose, which is classified at the steps).
  bool by_swing = false;
  bool swinging = swing_steps_.swinging(s.t_s);  // before: the last step ends the swing
  if (s.gyro_body_rad_s.allFinite()) {
    const Eigen::Vector3d& w = s.gyro_body_rad_s;
    by_swing = swing_steps_.update(s.t_s, w - w.dot(up) * up);
  }
  swinging = swinging || swing_steps_.swinging(s.t_s);
  if (by_acc || by_swing) {
    if (s.t_s - walk_.last_event_t_s > params_.walk_pause_s) walk_ = {};  // a new walk
    walk_.last_event_t_s = s.t_s;
    walk_.swing_events += by_swing ? 1 : 0;
  }
  const bool swing = s.gyro_body_rad_s.allFinite() && swinging;
  if (!(swing ? by_swing : by_acc)) return false;
  // The arm turns at a heel strike, the acceleration's valley closes a step just after one:
  // when one detector takes over from the other, a step less than half an interval after the
  // last one is that same step.
  if (swing != last_step_by_swing_ && last_step_t_s >= 0.0 &&
      s.t_s - last_step_t_s < 0.5 * std::max(interval_s, swing_steps_.half_swing_s()))
    return false;
  // The two detectors mark a step at different moments of it (the acceleration's valley is
  // confirmed 0.0-0.4 s after the strike, the arm's turn ~0.05 s): the interval across a handoff
  // is no cadence.
  source.handoff = swing != last_step_by_swing_;
  source.after_stand = last_step_t_s >= 0.0 && recent.quiet_between(last_step_t_s, s.t_s);
  // A walk after a stand (the phone still since the last step) begins with its first event
  // held until a second follows within walk_start_intervals with no stand between: a hand
  // moving the phone (putting it away, lifting it to the ear) makes one event, or two far apart.
  if (params_.walk_start_intervals > 0.0 && interval_s > 0.0 && source.after_stand) {
    const bool confirmed = start_pending_t_s_ >= 0.0 &&
                           s.t_s - start_pending_t_s_ < params_.walk_start_intervals * interval_s &&
                           !recent.quiet_between(start_pending_t_s_, s.t_s);
    if (!confirmed) {
      start_pending_t_s_ = s.t_s;
      return false;
    }
    start_pending_t_s_ = -1.0;
    ++source.backfill;      // the held event
    ++walk_.steps;          // (a swinging start's backfill must know it was counted)
    source.handoff = true;  // and no cadence across the stand
  }
  last_step_by_swing_ = swing;
  // A walk that starts swinging: the swing is recognised after two half swings, and the
  // acceleration may have missed the steps before (the pendulum lifts every valley above the
  // standing mean). The arm's turns since the walk began say how many: they are counted with
  // this step, if the walk is that young (its first kBackfillEvents turns).
  constexpr int kBackfillEvents = 8;
  if (swing && !walk_.backfilled && walk_.swing_events <= kBackfillEvents)
    source.backfill += std::max(0, walk_.swing_events - walk_.steps - 1);
  if (swing) walk_.backfilled = true;
  ++walk_.steps;
  ev.t_s = swing ? swing_steps_.step_t_s() : s.t_s;
  return true;
}

}  // namespace telltale::fusion
