#include "telltale/fusion/handheld/walking_yaw.hpp"

namespace telltale::fusion {

void WalkingHeading::update(double t_s, const Eigen::Vector3d& gyro_unbiased,
                            const Eigen::Vector3d& bias, const Eigen::Vector3d& up) {
  const double dt = started_ ? t_s - last_t_s_ : 0.0;
  if (dt > 0.0 && dt < 1.0) {
    yaw_rad_ += forward_.update(gyro_unbiased, dt, up);
    bias_yaw_rad_ += bias.dot(up) * dt;
    up_s_ += up * dt;
  } else {
    forward_.restart();  // the start or a gap: level again, nothing turned
    forward_.update(gyro_unbiased, 0.0, up);
  }
  started_ = true;
  last_t_s_ = t_s;
  const std::size_t i = (hist_head_ + hist_size_) % kHistory;
  hist_t_[i] = t_s;
  hist_yaw_[i] = yaw_rad_;
  hist_bias_yaw_[i] = bias_yaw_rad_;
  hist_up_s_[i] = up_s_;
  if (hist_size_ < kHistory)
    ++hist_size_;
  else
    hist_head_ = (hist_head_ + 1) % kHistory;
}

WalkingHeading::At WalkingHeading::at(double t_s) const {
  if (hist_size_ == 0) return {heading_rad(), bias_yaw_rad_, up_s_};
  // Newest first: the last sample at or before t_s (the oldest kept if t_s is older).
  std::size_t i = hist_head_;
  for (std::size_t k = hist_size_; k-- > 0;) {
    const std::size_t j = (hist_head_ + k) % kHistory;
    if (hist_t_[j] <= t_s) {
      i = j;
      break;
    }
  }
  return {offset_rad_ - hist_yaw_[i], hist_bias_yaw_[i], hist_up_s_[i]};
}

}  // namespace telltale::fusion
