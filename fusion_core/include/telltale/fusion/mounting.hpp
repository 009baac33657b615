#pragma once
/// \file
/// How the instrument is installed: an axis remap from the sensor's axes to the boat's FLU axes,
/// and heel/pitch offsets that zero the reading with the boat level at the dock.

#include <Eigen/Core>
#include <optional>
#include <string>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

struct Mounting {
  /// boat = remap * sensor. Identity when the sensor's axes already are FLU.
  Eigen::Matrix3d remap = Eigen::Matrix3d::Identity();
  double heel_offset_deg = 0.0;   ///< subtracted from the fused heel
  double pitch_offset_deg = 0.0;  ///< subtracted from the fused pitch

  /// Rotates a sample's gyro and accelerometer into the boat frame.
  [[nodiscard]] ImuSample apply(const ImuSample& s) const {
    return {s.t_s, remap * s.gyro_body_rad_s, remap * s.acc_body_m_s2};
  }
};

/// Parses "x=-y,y=x,z=z" (each boat axis from a signed sensor axis). Nothing unless the result is
/// a proper rotation (a permutation with signs and determinant +1).
[[nodiscard]] std::optional<Eigen::Matrix3d> parse_axis_remap(const std::string& spec);

}  // namespace telltale::fusion
