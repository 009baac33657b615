#pragma once
/// \file
/// PDR stage: the track (seed 003 eq. (11), with our revisions). Owns the position and what is
/// needed to move steps already laid when an estimate they were laid with improves: the
/// displacement of the pose's steps (turned with a better yaw correction), each step's
/// sensitivity to the hard-iron offset (moved with a better offset), and the steps of a pose
/// switch (re-laid with the heading each really had, SwitchRelay). Position is x east, y north
/// (m) from the start; headings clockwise from north.
///
/// Memory: fixed-size Eigen types, no heap.

#include <array>
#include <cstddef>
#include <optional>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/phone_pose.hpp"

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

/// A laid step, as a pose switch's re-laying needs it.
struct SwitchStep {
  double length_m = 0.0;
  double laid_rad = 0.0;       ///< heading it was laid with
  double old_frame_rad = 0.0;  ///< heading filter's heading (pose before the switch)
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< mean tracked up, sensor frame
  std::size_t slot = 0;                           ///< which foot (the waveform slot)
  /// Over the step, sums of unit (east, north) vectors of the horizontal sensor x and -z axes:
  /// the walking direction if the pose's forward axis is that one.
  std::array<Eigen::Vector2d, 2> axis_sum{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
};

/// The steps of a pose switch, and the last steps laid before one (a switch is seen one or two
/// steps after the phone began to move, so those are re-laid with it).
class SwitchRelay {
 public:
  static constexpr std::size_t kMaxSteps = 32;
  static constexpr std::size_t kLookback = 2;
  /// A switch was detected (`ups`: each foot's up now): the last steps join it, and the up
  /// direction before them is the old pose's. Returns how many joined.
  std::size_t begin(const std::array<Eigen::Vector3d, 2>& ups);
  /// A step laid during the switch (dropped past kMaxSteps).
  void add(const SwitchStep& laid) {
    if (count_ < kMaxSteps) steps_[count_++] = laid;
  }
  /// A step laid outside a switch; `ups_before`: each foot's up before it.
  void keep_last(const SwitchStep& laid, const std::array<Eigen::Vector3d, 2>& ups_before);
  [[nodiscard]] bool empty() const { return count_ == 0; }
  void clear() { count_ = 0; }
  /// Re-lays the switch's steps on `track` for the phone now in `pose` (`ups`: each foot's
  /// steady up now; `tilt_deg`: how far from it an up is another orientation); `stand_in_rad`
  /// the heading that stood in during the switch, `heading_after` the heading of the step
  /// after it (none: the switch goes on).
  void relay(Track& track, const std::array<Eigen::Vector3d, 2>& ups,
             std::optional<double> stand_in_rad, std::optional<double> heading_after,
             PhonePose pose, double tilt_deg);
  /// The last steps of the pose (`pose_steps` of them at most) were turned by `d_rad`.
  void turn_last(double d_rad, std::size_t pose_steps);

 private:
  std::array<SwitchStep, kMaxSteps> steps_{};
  std::size_t count_ = 0;
  std::array<Eigen::Vector3d, 2> ups_before_switch_{Eigen::Vector3d::UnitZ(),
                                                    Eigen::Vector3d::UnitZ()};
  std::array<SwitchStep, kLookback> last_{};  ///< newest last
  std::array<std::array<Eigen::Vector3d, 2>, kLookback> last_ups_before_{};
  std::size_t last_count_ = 0;
};

}  // namespace telltale::fusion
