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
      sensors_(params.gyro_bias, params.calibrate_mag, params.hard_iron),
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
  track_.lay(len, heading, true, sensors_.mag_calibration().offset_uT());
  out_.heading_deg = heading * 180.0 / M_PI;
}

const PdrOutput& FootPdr::update(const ImuSample& raw, const Eigen::Vector3d& mag_uT) {
  out_.step = false;
  ImuSample s;
  Eigen::Vector3d mag;
  if (!sensors_.prepare(raw, mag_uT, diag_, s, mag)) return out_;
  diag_.still_windows = sensors_.still_windows();
  out_.t_s = raw.t_s;  // the caller's clock; the stages run on s.t_s, the local one
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
