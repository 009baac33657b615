#include "telltale/fusion/trunk_pdr.hpp"

#include <cmath>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/handheld/walk_ratio.hpp"
#include "telltale/fusion/pdr/walking_heading.hpp"

namespace telltale::fusion {

TrunkPdr::TrunkPdr(Params params)
    : params_(params),
      sensors_(params.gyro_bias, params.calibrate_mag, params.hard_iron),
      attitude_(params.attitude),
      steps_(params.steps),
      motion_(params.step),
      cadence_(params.min_step_interval_s) {}

void TrunkPdr::lay(double length_m, double yaw_rad) {
  if (!oriented_) {
    oriented_ = true;
    if (orient_sin_ != 0.0 || orient_cos_ != 0.0)
      orient_rad_ = std::atan2(orient_sin_, orient_cos_);
  }
  const double heading = wrap_2pi(orient_rad_ - yaw_rad);
  out_.x_m += length_m * std::sin(heading);
  out_.y_m += length_m * std::cos(heading);
  out_.distance_m += length_m;
  out_.last_step_length_m = length_m;
  out_.heading_deg = heading * 180.0 / M_PI;
}

void TrunkPdr::on_step(double t_s) {
  ++out_.steps;
  out_.step = true;
  cadence_.at_step(t_s, 1.0, true);
  set_cadence(out_, cadence_.interval_s());
  const double f = out_.step_hz;
  const double prev = last_step_t_s_;
  last_step_t_s_ = t_s;
  if (prev < 0.0 || t_s - prev > params_.max_step_s) {
    // A walk's first heel strike closes no step of this walk: laid with the next.
    first_pending_ = true;
    last_length_m_ = 0.0;
    ++diag_.walks;
    return;
  }
  const TrunkStep st = motion_.step(prev, t_s, params_.height_m);
  double length = st.length_m;
  if (!st.ok) {
    ++diag_.unmeasured;
    length = last_length_m_ > 0.0 ? last_length_m_
                                  : walk_ratio_step_length_m(params_.height_m, f > 0.0 ? f : 1.8);
  } else {
    last_length_m_ = length;
  }
  if (first_pending_) {
    first_pending_ = false;
    lay(length, st.yaw_rad);
  }
  lay(length, st.yaw_rad);
}

const PdrOutput& TrunkPdr::update(const ImuSample& raw, const Eigen::Vector3d& mag_uT) {
  ImuSample s;
  Eigen::Vector3d mag;
  if (!sensors_.arrive(raw, mag_uT, diag_, out_, s, mag)) return out_;
  if (!s.gyro_body_rad_s.allFinite()) return out_;  // no gyro: no vertical, no heading
  attitude_.update(s);
  const Eigen::Vector3d& up = attitude_.state().up_body;
  const double dt = have_t_ ? s.t_s - last_t_s_ : 0.0;
  have_t_ = true;
  last_t_s_ = s.t_s;
  // The yaw: the rate about the vertical, integrated, with the bias the stands measured
  // (SensorPrep), not the attitude filter's. A bias about the vertical moves no vertical, so in
  // motion the filter learns it only through the sensor's tilt off the vertical, from the
  // low-pass's noise: on a lower back that never stood still (IPOL 4-4) its estimate on the
  // near-vertical axis ran to 7 deg/s, and the track turned 20-40 deg too far in a U-turn (end
  // 5.3 m from the start, 1.7 m with the stands' bias). Not over a gap the gate flagged.
  if (dt > 0.0 && dt <= params_.attitude.max_gap_s)
    yaw_rad_ = std::remainder(yaw_rad_ + s.gyro_body_rad_s.dot(up) * dt, 2.0 * M_PI);
  motion_.add(s.t_s, s.acc_body_m_s2.dot(up), yaw_rad_);
  // North, before the first step: the magnetometer's heading of the x axis plus the yaw.
  if (!oriented_ && mag.allFinite()) {
    const double h = HeadingFilter::magnetic_heading_rad(mag, up);
    if (std::isfinite(h)) {
      orient_sin_ += std::sin(h + yaw_rad_);
      orient_cos_ += std::cos(h + yaw_rad_);
    }
  }
  StepEvent ev;
  if (steps_.update(s, ev)) on_step(ev.t_s);
  return out_;
}

}  // namespace telltale::fusion
