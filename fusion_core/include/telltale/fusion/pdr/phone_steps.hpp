#pragma once
/// \file
/// PDR stage (phone pipeline): the phone's two step detectors, the acceleration's peaks and
/// valleys (any pose) and the arm's turns (while the phone swings), and which of them speaks for
/// the steps. What their events stand for (a step, none, several) is the step clock's to say
/// (step_clock.hpp). The foot pipeline (FootPdr) uses GaitPhaseStepDetector alone.
///
/// Memory: the detectors' fixed-size buffers, no heap.

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/peak_valley_steps.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {

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

class PhoneSteps {
 public:
  PhoneSteps() : acc_steps_(acc_step_params()) {}
  /// One sample (gyro bias removed); `up` the tracked up direction in the sensor frame.
  PhoneEvents update(const ImuSample& s, const Eigen::Vector3d& up);
  [[nodiscard]] const StepDiagnostics& diagnostics() const { return acc_steps_.diagnostics(); }

 private:
  /// The peak-valley detector without its handled-phone rule (PeakValleyStepParams::
  /// max_tilt_deg): here the step clock's walk-start hold and the stand decide what a handled
  /// phone's events are, and the rule on top of them cost the simulated loops' pose switches
  /// steps (2 of 5682) and closure (90th percentile 1.76 -> 1.98 %).
  static PeakValleyStepParams acc_step_params() {
    PeakValleyStepParams p;
    p.max_tilt_deg = 0.0;
    return p;
  }
  PeakValleyStepDetector acc_steps_;
  SwingStepDetector swing_steps_;  ///< steps while the phone swings (its turns)
};

}  // namespace telltale::fusion
