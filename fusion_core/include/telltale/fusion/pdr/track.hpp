#pragma once
/// \file
/// PDR stage: the track (seed 003 eq. (11), with our revisions). Owns the position and what is
/// needed to move steps already laid when an estimate they were laid with improves: the
/// displacement of the pose's steps (turned with a better yaw correction) and each step's
/// sensitivity to the hard-iron offset (moved with a better offset). Position is x east, y north
/// (m) from the start; headings clockwise from north.
///
/// Memory: fixed-size Eigen types, no heap.

#include <cstddef>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

struct TrackParams {
  /// Re-lay steps already walked when an estimate they were laid with improves (our addition):
  /// the hard-iron offset (each step's heading moves by its sensitivity to the offset, so the
  /// leg walked before the first corner calibrated the magnetometer is corrected too) and the
  /// pose's yaw from the walking direction (every step since the pose began turns with it).
  bool revise = true;
};

class Track {
 public:
  using Params = TrackParams;
  /// `mag_calibrated`: the hard-iron offset is learnt (otherwise it never changes).
  Track(Params params, bool mag_calibrated)
      : params_(params), revise_offset_(params.revise && mag_calibrated) {}
  /// Per sample: how the heading moves per uT of hard-iron offset (rad/uT, sensor frame).
  void add_offset_sensitivity(const Eigen::Vector3d& dheading_doffset) {
    sens_sum_ += dheading_doffset;
    ++sens_n_;
  }
  /// A step ended: its samples' sensitivity becomes the step's.
  void begin_step();
  /// A step walked before the first heading: laid with the next one (a straight start).
  void hold(double length_m) { pending_m_ += length_m; }
  /// Lays a step (and what was held) along `heading_rad`; `in_pose`: laid in the pose's own
  /// walking frame (not during a switch), so it turns with the pose's yaw correction.
  void lay(double length_m, double heading_rad, bool in_pose, const Eigen::Vector3d& offset_uT);
  /// Turns the steps laid in this pose so far to a new yaw correction `corr_rad`; returns the
  /// turn (rad, 0: none).
  double turn_pose(double corr_rad);
  /// Moves the track (a step re-laid).
  void shift(double east_m, double north_m) {
    x_m_ += east_m;
    y_m_ += north_m;
  }
  /// A step re-laid in the pose's frame: it turns with the pose from now on.
  void add_to_pose(const Eigen::Vector2d& displacement_m) { pose_disp_ += displacement_m; }
  /// A new pose: its steps start without a yaw correction (the old pose's keep theirs).
  void new_pose();
  [[nodiscard]] double x_m() const { return x_m_; }
  [[nodiscard]] double y_m() const { return y_m_; }
  /// Steps laid in this pose.
  [[nodiscard]] std::size_t pose_steps() const { return pose_steps_; }

 private:
  /// Moves the track by what the hard-iron offset changes in every step laid so far.
  void revise_offset(const Eigen::Vector3d& offset_uT);
  Params params_;
  bool revise_offset_;
  double x_m_ = 0.0, y_m_ = 0.0;
  double pending_m_ = 0.0;  ///< distance walked before the first heading
  // Revision for the pose's yaw: displacement of the steps laid in this pose (as laid), the
  // correction they carry, and how many there are.
  Eigen::Vector2d pose_disp_ = Eigen::Vector2d::Zero();
  double pose_corr_rad_ = 0.0;
  std::size_t pose_steps_ = 0;
  // Revision for the hard-iron offset: over all laid steps, sum of L dpos/dheading
  // (dheading/doffset)^T (east, north per uT) and of the same times the offset each was laid
  // with; the correction already applied. Over the current step: sum of dheading/doffset, and
  // over the last step its mean.
  Eigen::Matrix<double, 2, 3> mag_a_ = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Vector2d mag_c_ = Eigen::Vector2d::Zero(), mag_applied_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d sens_sum_ = Eigen::Vector3d::Zero(), step_sens_ = Eigen::Vector3d::Zero();
  int sens_n_ = 0;
  bool have_step_sens_ = false;
};

}  // namespace telltale::fusion
