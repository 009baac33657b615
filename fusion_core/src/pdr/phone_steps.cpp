#include "telltale/fusion/pdr/phone_steps.hpp"

namespace telltale::fusion {

PhoneEvents PhoneSteps::update(const ImuSample& s, const Eigen::Vector3d& up) {
  PhoneEvents e;
  e.t_s = s.t_s;
  StepEvent ev;
  e.by_acc = acc_steps_.update(s, ev);
  // While the phone swings (a swinging arm; a thigh, for a phone in a trouser pocket) its turns
  // count the steps (SwingStepDetector), whatever the pose: in arm swing the hand's pendulum
  // swamps the trunk's acceleration and the peak-valley detector loses steps, or the whole
  // walk at a slow pace (and with it the pose, which is classified at the steps).
  bool swinging = swing_steps_.swinging(s.t_s);  // before: the last step ends the swing
  const bool gyro = s.gyro_body_rad_s.allFinite();
  if (gyro) {
    const Eigen::Vector3d& w = s.gyro_body_rad_s;
    e.by_swing = swing_steps_.update(s.t_s, w - w.dot(up) * up);
  }
  swinging = swinging || swing_steps_.swinging(s.t_s);
  e.swing = gyro && swinging;
  e.swing_step_t_s = swing_steps_.step_t_s();
  e.half_swing_s = swing_steps_.half_swing_s();
  return e;
}

}  // namespace telltale::fusion
