#include "telltale/fusion/handheld/track_relay.hpp"

#include <cmath>

namespace telltale::fusion {

double relaid_heading_rad(const GyroLaidStep& step, const GyroLaidStep& anchor,
                          const Eigen::Vector3d& bias_rad_s) {
  // yaw = (raw gyro . up) integrated - bias_yaw; with the constant bias b instead of the biases
  // in use it is larger by bias_yaw - b . up_s, and the heading (offset - yaw) smaller by that;
  // the anchor keeps its heading.
  const auto moved = [&bias_rad_s](const GyroLaidStep& s) {
    return s.bias_yaw_rad - bias_rad_s.dot(s.up_s);
  };
  return step.gyro_heading_rad - (moved(step) - moved(anchor));
}

Eigen::Vector2d TrackRelay::displacement(const GyroLaidStep& s) const {
  const double h = relaid_heading_rad(s, anchor_, bias_);
  return s.length_m * Eigen::Vector2d(std::sin(h), std::cos(h));
}

TrackRelay::Laid TrackRelay::lay(const GyroLaidStep& step, const Eigen::Vector3d& bias_in) {
  const Eigen::Vector3d bias_rad_s = bias_in.allFinite() ? bias_in : bias_;
  if (!anchored_) {
    anchor_ = step;
    anchored_ = true;
    bias_ = bias_rad_s;
  }
  // The oldest steps leave the window with the bias they were last laid with.
  while (size_ > 0 && (size_ == kCapacity || step.t_s - ring_[head_].t_s > window_s_)) {
    const Eigen::Vector2d d = displacement(ring_[head_]);
    folded_ += d;
    sum_ -= d;
    head_ = (head_ + 1) % kCapacity;
    --size_;
  }
  ring_[(head_ + size_) % kCapacity] = step;
  ++size_;
  if (bias_rad_s != bias_) {
    // A stand has measured the bias again: the window laid anew with it (once per stand; the
    // bias does not change while walking).
    bias_ = bias_rad_s;
    sum_.setZero();
    for (std::size_t k = 0; k < size_; ++k) sum_ += displacement(ring_[(head_ + k) % kCapacity]);
  } else {
    sum_ += displacement(step);
  }
  const Eigen::Vector2d p = folded_ + sum_;
  return {p.x(), p.y(), relaid_heading_rad(step, anchor_, bias_)};
}

}  // namespace telltale::fusion
