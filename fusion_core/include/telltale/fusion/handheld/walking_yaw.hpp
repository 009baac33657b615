#pragma once
/// \file
/// Hand-held phone PDR stage (HandheldPdr, handheld_pdr.hpp): the phone's yaw about the
/// vertical (WalkingHeading), the bias-corrected gyro integrated about the up direction, with a
/// short history for steps confirmed late. Not the four-pose PDR's walking heading
/// (pdr/walking_heading.hpp, gyro + magnetometer): here the magnetometer never steers the yaw.
///
/// Memory: fixed-size arrays, no heap.

#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "telltale/fusion/forward_axis_yaw.hpp"
#include "telltale/fusion/handheld/stand_bias.hpp"

namespace telltale::fusion {

/// The phone's yaw about the vertical: the turn of its forward axis (kHandheldForward, the axis
/// the magnetometer orients the track by) about the vertical, counter-clockwise seen from above,
/// from the gyro less the bias (ForwardAxisYaw says why not the rate about the vertical);
/// heading = start - yaw. A short history lets a step confirmed late take the heading
/// it had when it was walked. Beside the yaw it integrates what relay_track needs to lay the
/// walk again with another bias: the yaw the bias in use took off, integral of bias . up dt,
/// and the integral of up dt (the yaw any constant bias b takes off is b . that integral).
class WalkingHeading {
 public:
  static constexpr std::size_t kHistory = 1024;  ///< samples: 20 s at 50 Hz
  /// `gyro_unbiased` = the gyro minus `bias`.
  void update(double t_s, const Eigen::Vector3d& gyro_unbiased, const Eigen::Vector3d& bias,
              const Eigen::Vector3d& up);
  /// Heading (clockwise from north, rad) now.
  [[nodiscard]] double heading_rad() const { return offset_rad_ - yaw_rad_; }
  /// The heading and the two integrals at an earlier time within the history (the last sample
  /// at or before it; the oldest kept if it is older).
  struct At {
    double heading_rad = 0.0;
    double bias_yaw_rad = 0.0;
    Eigen::Vector3d up_s = Eigen::Vector3d::Zero();
  };
  [[nodiscard]] At at(double t_s) const;
  /// The yaw integrated so far (counter-clockwise, rad) and the offset heading = offset - yaw.
  [[nodiscard]] double yaw_rad() const { return yaw_rad_; }
  void set_offset(double offset_rad) { offset_rad_ = offset_rad; }

 private:
  double yaw_rad_ = 0.0, offset_rad_ = 0.0, last_t_s_ = 0.0;
  double bias_yaw_rad_ = 0.0;
  Eigen::Vector3d up_s_ = Eigen::Vector3d::Zero();
  bool started_ = false;
  ForwardAxisYaw forward_{kHandheldForward};
  std::array<double, kHistory> hist_yaw_{};
  std::array<double, kHistory> hist_bias_yaw_{};
  std::array<Eigen::Vector3d, kHistory> hist_up_s_{};
  std::array<double, kHistory> hist_t_{};
  std::size_t hist_head_ = 0, hist_size_ = 0;
};

}  // namespace telltale::fusion
