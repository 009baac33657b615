#include "telltale/fusion/handheld_pdr.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion {

void relay_track(std::span<HandheldStep> steps, const Eigen::Vector3d& bias_rad_s) {
  if (steps.empty()) return;
  const GyroLaidStep anchor = steps.front().gyro;
  double x = 0.0, y = 0.0;
  for (auto& s : steps) {
    const double heading = relaid_heading_rad(s.gyro, anchor, bias_rad_s);
    x += s.length_m * std::sin(heading);
    y += s.length_m * std::cos(heading);
    s.x_m = x;
    s.y_m = y;
    s.heading_deg = wrap_360_deg(heading * (180.0 / M_PI));
  }
}

// ---------------------------------------------------------------------------------------------
HandheldPdr::HandheldPdr(Params p)
    : params_(p),
      att_(p.attitude),
      bias_(p.bias),
      detector_(p.steps) {}

int HandheldPdr::update(const ImuSample& sample, const Eigen::Vector3d& mag_uT) {
  ImuSample s = sample;
  s.t_s = clock_.to_local(sample.t_s);  // every stage on the local clock (LocalClock says why)
  if (gate_imu_sample(s, ImuGateParams{}, have_t_, last_t_s_, diag_).verdict ==
      ImuVerdict::kReject) {
    return 0;
  }
  att_.update(s);
  const Eigen::Vector3d up = att_.state().up_body;
  bias_.update(s, up, mag_uT);
  const Eigen::Vector3d w = s.gyro_body_rad_s - bias_.bias_rad_s();
  heading_.update(s.t_s, w, bias_.bias_rad_s(), up);

  // The track's orientation, once: while standing before the first walk, each magnetometer
  // sample says offset = (magnetic heading of the forward axis) + yaw (circular mean).
  if (!oriented_ && params_.orient_with_mag && bias_.quiet() && mag_uT.allFinite()) {
    const double h = handheld_magnetic_heading(mag_uT, up, kHandheldForward);
    if (std::isfinite(h)) {
      const double off = h + heading_.yaw_rad();
      mag_offset_sum_ += Eigen::Vector2d(std::cos(off), std::sin(off));
      ++mag_n_;
    }
  }

  const int n = detector_.update(s, up);
  if (n > 0 && !oriented_) {
    oriented_ = true;
    if (mag_n_ > 0) heading_.set_offset(std::atan2(mag_offset_sum_.y(), mag_offset_sum_.x()));
  }
  for (int k = 0; k < n; ++k) {
    const auto& c = detector_.steps()[static_cast<std::size_t>(k)];
    if (c.interval_s > 0.0) {
      intervals_[static_cast<std::size_t>(interval_n_ % 4)] = c.interval_s;
      ++interval_n_;
    }
    // Cadence: the mean of the last four intervals (the walk's own for its first step).
    double interval = detector_.interval_s();
    if (interval_n_ > 0) {
      const int m = std::min(interval_n_, 4);
      double sum = 0.0;
      for (int i = 0; i < m; ++i) sum += intervals_[static_cast<std::size_t>(i)];
      interval = sum / m;
    }
    const double hz = interval > 0.0 ? 1.0 / interval : 1.8;
    const double len =
        params_.step_scale * walk_ratio_step_length_m(params_.height_m, hz, params_.length);
    const WalkingHeading::At at = heading_.at(c.t_s);
    const GyroLaidStep gyro{c.t_s, len, at.heading_rad, at.bias_yaw_rad, at.up_s};
    const TrackRelay::Laid laid = relay_.lay(gyro, bias_.bias_rad_s());
    last_.t_s = clock_.to_caller(c.t_s);
    last_.x_m = laid.x_m;
    last_.y_m = laid.y_m;
    last_.heading_deg = wrap_360_deg(laid.heading_rad * 180.0 / M_PI);
    last_.length_m = len;
    last_.step_hz = hz;
    last_.gyro = gyro;
    last_.distance_m += len;
    ++last_.steps;
    laid_[static_cast<std::size_t>(k)] = last_;
  }
  return n;
}

}  // namespace telltale::fusion
