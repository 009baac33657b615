#pragma once
/// \file
/// Hand-held phone PDR stage (HandheldPdr, handheld_pdr.hpp): the track, laid with the best gyro
/// bias known. The bias is a constant of the gyro over a walk (it drifts with temperature over
/// tens of minutes), and each stand measures it; a step walked before a stand was laid with the
/// bias known then. The heading the gyro gave a step with the biases in use is off, against the
/// heading the constant bias b gives it, by the yaw the two part by since the track's first step
/// (the anchor, whose heading the magnetometer set): (integral of bias-in-use . up) - b .
/// (integral of up), both kept per step by WalkingHeading.
///
///   relay_track(steps, b): a walk reviewed after it ends (fusion_cli pdr, steps-eval), every
///     step laid again with the bias the walk ended with.
///   TrackRelay: the live track (wearable_node), each step laid with the bias known at it, and
///     with it the steps before it that the stands since have corrected: the track ends where
///     relay_track would put it with that bias. After a stand the position jumps by what the
///     stand has mended.
///
/// Memory: TrackRelay keeps the last kCapacity steps, fixed-size, no heap.

#include <Eigen/Core>
#include <array>
#include <cstddef>

namespace telltale::fusion {

/// One step as the gyro laid it: the heading with the biases in use (rad, clockwise from
/// north), and WalkingHeading's integrals at it (the yaw the biases in use took off, rad; the
/// integral of the up direction, s).
struct GyroLaidStep {
  double t_s = 0.0;
  double length_m = 0.0;
  double gyro_heading_rad = 0.0;
  double bias_yaw_rad = 0.0;
  Eigen::Vector3d up_s = Eigen::Vector3d::Zero();
};

/// The heading `step` has with the constant bias b from `anchor` (the track's first step) on.
[[nodiscard]] double relaid_heading_rad(const GyroLaidStep& step, const GyroLaidStep& anchor,
                                        const Eigen::Vector3d& bias_rad_s);

class TrackRelay {
 public:
  /// 2048 steps: 15 min of a brisk walk (2.3 steps/s).
  static constexpr std::size_t kCapacity = 2048;
  /// Steps older than window_s (or beyond kCapacity) keep where they were laid: the bias they
  /// were walked with has drifted since (900 s: the tens of minutes a MEMS gyro's bias takes to
  /// move with its temperature).
  explicit TrackRelay(double window_s = 900.0) : window_s_(window_s) {}
  struct Laid {
    double x_m = 0.0, y_m = 0.0;  ///< east, north of the start
    double heading_rad = 0.0;     ///< the step's, with the bias
  };
  /// Lays `step` with the bias known now (`bias_rad_s`), the steps in the window with it. A
  /// bias that is not finite is no measurement: the last one stays.
  Laid lay(const GyroLaidStep& step, const Eigen::Vector3d& bias_rad_s);

 private:
  [[nodiscard]] Eigen::Vector2d displacement(const GyroLaidStep& s) const;
  double window_s_;
  std::array<GyroLaidStep, kCapacity> ring_{};
  std::size_t head_ = 0, size_ = 0;
  GyroLaidStep anchor_;
  bool anchored_ = false;
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();    ///< the bias sum_ was laid with
  Eigen::Vector2d folded_ = Eigen::Vector2d::Zero();  ///< the steps that left the window
  Eigen::Vector2d sum_ = Eigen::Vector2d::Zero();     ///< the window's, with bias_
};

}  // namespace telltale::fusion
