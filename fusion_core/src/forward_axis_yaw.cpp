#include "telltale/fusion/forward_axis_yaw.hpp"

#include <cmath>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

ForwardAxisYaw::ForwardAxisYaw(const Eigen::Vector3d& forward_body)
    : forward_(forward_body), forward_norm2_(forward_body.squaredNorm()) {}

void ForwardAxisYaw::horizontal(const Eigen::Vector3d& up, Eigen::Vector2d& h, bool& usable) const {
  h = Eigen::Vector2d(forward_.dot(ref_), forward_.dot(up.cross(ref_)));
  // More than 30 deg from the vertical: |horizontal| > sin(30 deg) |f|.
  usable = h.squaredNorm() > 0.25 * forward_norm2_;
}

double ForwardAxisYaw::update(const Eigen::Vector3d& rate_rad_s, double dt_s,
                              const Eigen::Vector3d& up) {
  if (!started_) {
    ref_ = perpendicular(up);
    horizontal(up, h_prev_, usable_prev_);
    started_ = true;
    return 0.0;
  }
  // The reference seen from the body turning by theta over the sample (Rodrigues, rotated by
  // -theta): v cos(a) - sin(a) / a (theta x v) + (1 - cos(a)) / a^2 theta (theta . v), a =
  // |theta|; the three factors by their series up to 0.2 rad (a phone at 50 Hz turning at
  // 10 rad/s; error < 1e-8 rad), exactly beyond ...
  const Eigen::Vector3d theta = rate_rad_s * dt_s;
  const double n = theta.squaredNorm();
  double c = 0.0, s = 0.0, k = 0.0;
  if (n <= 0.04) {
    c = 1.0 - n * (0.5 - n * (1.0 / 24.0));
    s = 1.0 - n * (1.0 / 6.0 - n * (1.0 / 120.0));
    k = 0.5 - n * (1.0 / 24.0 - n * (1.0 / 720.0));
  } else {
    const double a = std::sqrt(n);
    c = std::cos(a);
    s = std::sin(a) / a;
    k = (1.0 - c) / n;
  }
  Eigen::Vector3d v = c * ref_ - s * theta.cross(ref_) + (k * theta.dot(ref_)) * theta;
  // ... held horizontal and unit: the smallest correction that keeps it level with the
  // vertical as the attitude filter has it (it moves the axis's angle only to second order).
  v -= v.dot(up) * up;
  const double n2 = v.squaredNorm();
  ref_ = n2 > 1e-6 ? Eigen::Vector3d(v / std::sqrt(n2)) : perpendicular(up);
  Eigen::Vector2d h;
  bool usable = false;
  horizontal(up, h, usable);
  double turn = 0.0;
  if (usable && usable_prev_) {
    // The angle from the last horizontal direction to this one (cross, dot: no wrap).
    turn = fast_atan2(h_prev_.x() * h.y() - h_prev_.y() * h.x(), h_prev_.dot(h));
  } else {
    turn = rate_rad_s.dot(up) * dt_s;  // no direction to follow: the turn of the body
  }
  h_prev_ = h;
  usable_prev_ = usable;
  return turn;
}

}  // namespace telltale::fusion
