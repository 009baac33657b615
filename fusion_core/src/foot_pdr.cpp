#include "telltale/fusion/foot_pdr.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/pdr.hpp"

namespace telltale::fusion {
namespace {

/// The detector sees one foot: each event closes a stride, two steps.
constexpr double kStepsPerStride = 2.0;

}  // namespace

FootPdr::FootPdr(Params params) : FootPdr(params, builtin_step_length_model()) {}

FootPdr::FootPdr(Params params, const StepLengthModel& lengths)
    : params_(params),
      step_length_(params.step_length, lengths),
      steps_(params.steps),
      cadence_(params.min_step_interval_s),
      heading_(params.heading),
      mag_cal_(params.hard_iron),
      gyro_bias_(params.gyro_bias),
      track_(params.track, params.calibrate_mag) {}

void FootPdr::on_stride(double t_s) {
  track_.begin_step();
  cadence_.at_step(t_s, kStepsPerStride, true);
  out_.steps += static_cast<std::size_t>(kStepsPerStride);
  if (cadence_.interval_s() > 0.0) {
    out_.step_hz = 1.0 / cadence_.interval_s();
    out_.cadence_spm = 60.0 * out_.step_hz;
  }
  const double f = out_.step_hz;
  out_.gait = f < 1.6 ? 0 : f < 1.95 ? 1 : f < 2.35 ? 2 : f < 2.75 ? 3 : 4;
  // The heading filter's circular mean over the stride (its heading if it had none).
  double heading = heading_.heading_rad();
  if (sum_sin_ != 0.0 || sum_cos_ != 0.0) heading = std::atan2(sum_sin_, sum_cos_);
  sum_sin_ = sum_cos_ = 0.0;
  heading = wrap_2pi(heading);
  // The first stride has no frequency yet: the person's usual walk.
  const double hz = out_.step_hz > 0.0 ? out_.step_hz : 1.8;
  const double step_m = step_length_.step_m(PhonePose::kHandHeld, hz);
  const double len = kStepsPerStride * step_m;
  out_.last_step_length_m = len;
  heading_.set_speed(step_m * hz);
  out_.distance_m += len;
  track_.lay(len, heading, true, mag_cal_.offset_uT());
  out_.heading_deg = heading * 180.0 / M_PI;
}

const PdrOutput& FootPdr::update(const ImuSample& raw, const Eigen::Vector3d& mag_uT) {
  out_.step = false;
  static constexpr ImuGateParams kGate{.gyro_required = false};
  if (gate_imu_sample(raw, kGate, have_t_, last_t_s_, diag_).verdict == ImuVerdict::kReject) {
    return out_;
  }
  ImuSample s = raw;
  if (s.gyro_body_rad_s.allFinite()) {
    gyro_bias_.add(s);
    diag_.still_windows = gyro_bias_.windows();
    s.gyro_body_rad_s -= gyro_bias_.bias_rad_s();
  }
  out_.t_s = s.t_s;
  Eigen::Vector3d mag = mag_uT;
  if (params_.calibrate_mag && mag.allFinite()) {
    // The hard-iron residual rotates with the foot, so its heading error changes with the
    // walking direction and does not cancel around a loop: remove it before the heading.
    mag_cal_.update(s.t_s, s.gyro_body_rad_s, mag);
    mag = mag_cal_.corrected(mag);
  }
  // The sensor's frame is the walking frame: a foot carries it one way.
  heading_.update(s.t_s, s.gyro_body_rad_s, s.acc_body_m_s2, mag);
  if (heading_.initialised()) {
    sum_sin_ += std::sin(heading_.heading_rad());
    sum_cos_ += std::cos(heading_.heading_rad());
    out_.heading_deg = heading_.heading_rad() * 180.0 / M_PI;
  }
  StepEvent ev;
  if (steps_.update(s, ev)) {
    on_stride(ev.t_s);
    out_.x_m = track_.x_m();
    out_.y_m = track_.y_m();
    out_.step = true;
  }
  return out_;
}

}  // namespace telltale::fusion
