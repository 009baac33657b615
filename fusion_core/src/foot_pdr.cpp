#include "telltale/fusion/foot_pdr.hpp"

#include <cmath>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/pdr/walking_heading.hpp"

namespace telltale::fusion {
namespace {

/// The detector sees one foot: each of its steps closes a stride, two steps.
constexpr double kStepsPerStride = 2.0;

}  // namespace

FootPdr::FootPdr(Params params)
    : params_(params),
      steps_(params.steps),
      ins_(params.ins),
      cadence_(params.min_step_interval_s),
      sensors_(params.gyro_bias, params.calibrate_mag, params.hard_iron) {}

void FootPdr::lay_stride(const Eigen::Vector2d& d) {
  if (!oriented_) {
    // The magnetometer's orientation; without one, the sensor's x axis at the start is north.
    oriented_ = true;
    orient_rad_ = orient_sin_ != 0.0 || orient_cos_ != 0.0 ? std::atan2(orient_sin_, orient_cos_)
                                                           : start_yaw_rad_;
  }
  const double length = d.norm();
  const double heading = wrap_2pi(orient_rad_ - std::atan2(d.y(), d.x()));
  out_.x_m += length * std::sin(heading);
  out_.y_m += length * std::cos(heading);
  out_.distance_m += length;
  out_.last_step_length_m = length / kStepsPerStride;
  out_.heading_deg = heading * 180.0 / M_PI;
  ++diag_.strides;
}

const PdrOutput& FootPdr::update(const ImuSample& raw, const Eigen::Vector3d& mag_uT) {
  ImuSample s;
  Eigen::Vector3d mag;
  if (!sensors_.arrive(raw, mag_uT, diag_, out_, s, mag)) return out_;
  if (!s.gyro_body_rad_s.allFinite()) return out_;  // no gyro: nothing to navigate with
  const double dt = have_t_ ? s.t_s - last_t_s_ : 0.0;
  have_t_ = true;
  last_t_s_ = s.t_s;
  const bool stride = ins_.update(s, dt);
  if (!have_start_yaw_ && ins_.started()) {
    have_start_yaw_ = true;
    start_yaw_rad_ = ins_.sensor_yaw_rad();
  }
  diag_.dropped_swings = ins_.dropped();
  if (stride) lay_stride(ins_.stride_m());
  // North, before the first stride: over the stance the magnetometer gives the sensor's x axis
  // a heading, and the INS the same axis an angle; their sum is the track's orientation.
  if (!oriented_ && ins_.started() && ins_.stance() && mag.allFinite()) {
    const Eigen::Vector3d up = ins_.up_body();
    const double h = HeadingFilter::magnetic_heading_rad(mag, up);
    if (std::isfinite(h)) {
      orient_sin_ += std::sin(h + ins_.sensor_yaw_rad());
      orient_cos_ += std::cos(h + ins_.sensor_yaw_rad());
    }
  }
  StepEvent ev;
  if (steps_.update(s, ev)) {
    cadence_.at_step(ev.t_s, kStepsPerStride, true);
    out_.steps += static_cast<std::size_t>(kStepsPerStride);
    set_cadence(out_, cadence_.interval_s());
    out_.step = true;
  }
  return out_;
}

}  // namespace telltale::fusion
