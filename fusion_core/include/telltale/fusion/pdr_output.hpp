#pragma once
/// \file
/// What a dead-reckoning pipeline publishes after a sample: the phone's (Pdr) and the foot's
/// (FootPdr) give the wearable node one message whatever the mount.

#include <cstddef>

#include "telltale/fusion/phone_pose.hpp"

namespace telltale::fusion {

/// Everything a node publishes after a sample.
struct PdrOutput {
  double t_s = 0.0;
  std::size_t steps = 0;     ///< steps of both feet
  double cadence_spm = 0.0;  ///< steps per minute (0 until two steps)
  double step_hz = 0.0;      ///< step frequency used for the step length
  double last_step_length_m = 0.0;
  double distance_m = 0.0;
  double x_m = 0.0;          ///< east of the start, m
  double y_m = 0.0;          ///< north of the start, m
  double heading_deg = 0.0;  ///< walking direction, clockwise from north
  PhonePose pose = PhonePose::kHandHeld;
  bool switching = false;  ///< a pose switch is in progress (heading held)
  int gait = 1;            ///< coarse gait from cadence: 0 slow walk .. 4 run
  bool step = false;       ///< a step completed at this sample
};

/// The coarse gait of a step frequency (Hz): 0 slow walk, 1 walk, 2 fast walk, 3 jog, 4 run.
[[nodiscard]] inline int gait_of_step_hz(double f) {
  return f < 1.6 ? 0 : f < 1.95 ? 1 : f < 2.35 ? 2 : f < 2.75 ? 3 : 4;
}

/// A step's cadence into `out`: the step frequency and cadence from the step interval when one
/// is known (> 0; else the last are kept), and the gait they make.
inline void set_cadence(PdrOutput& out, double interval_s) {
  if (interval_s > 0.0) {
    out.step_hz = 1.0 / interval_s;
    out.cadence_spm = 60.0 * out.step_hz;
  }
  out.gait = gait_of_step_hz(out.step_hz);
}

}  // namespace telltale::fusion
