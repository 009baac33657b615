#pragma once
/// \file
/// PDR stage (phone pipeline): pose-switch detection (seed 003). Owns the last two step
/// waveforms and the up direction tracked over each step, the switch's progress (detected,
/// settling, over) and the heading that stands in while it lasts, because a switch is seen by
/// comparing a step with the same foot's last and every later stage asks whether one is on.
/// What the switch's steps become is the track's (SwitchRelay), the pose after it the
/// classifier's.
///
/// Memory: fixed-size arrays, no heap.

#include <array>
#include <cstddef>
#include <optional>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/recent_samples.hpp"

namespace telltale::fusion {

struct PoseSwitchParams {
  double correlation = 0.5;    ///< step waveforms correlating less = pose switch...
  double tilt_deg = 15.0;      ///< ...if gravity also moved this much in the sensor frame
                               ///< (twice this much is a switch whatever the correlation)
  int exit_steps = 2;          ///< correlated steps needed to leave a switch
  int pose_window_steps = 10;  ///< steps after a switch to confirm the new pose
};

class PoseSwitch {
 public:
  using Params = PoseSwitchParams;
  using Wave = RecentSamples::Wave;
  enum class Event { kNone, kBegan, kSettling };
  explicit PoseSwitch(Params params) : params_(params) {}
  /// Per sample: the up direction the heading filter tracks (gyro, pulled toward the
  /// accelerometer with the turn's centripetal acceleration taken out), sensor frame.
  void add_up(const Eigen::Vector3d& up) { step_up_ += up; }
  /// At a step with waveform `w` (not the walk's first): compares it with the same foot's last.
  /// kBegan: a switch was detected (the caller gathers its steps: choose_stand_in after);
  /// kSettling: the phone is steady again, the new pose is to be confirmed.
  Event at_step(const Wave& w);
  /// The step is over (after at_step, if any): its up sum starts again.
  void end_step() { step_up_.setZero(); }
  /// If the 3 steps before the switch's `back` re-laid ones were straight (within
  /// `straight_deg` of their mean), their mean heading stands in during the switch.
  void choose_stand_in(std::size_t back, double straight_deg);
  /// A step while settling: past pose_window_steps with no confirmed pose, the switch ends.
  void count_settling_step() {
    if (settling_ && ++settling_steps_ > params_.pose_window_steps) end();
  }
  /// The switch is over (a pose was confirmed, or none was).
  void end() { settling_ = switching_ = false; }
  /// A step's heading laid outside a switch (the stand-in's candidates).
  void note_heading(double heading_rad);
  [[nodiscard]] bool switching() const { return switching_; }
  [[nodiscard]] bool settling() const { return settling_; }
  /// The heading chosen to stand in at the last switch, if any.
  [[nodiscard]] std::optional<double> stand_in_rad() const {
    return have_stand_in_ ? std::optional<double>(stand_in_rad_) : std::nullopt;
  }
  /// Each foot's mean tracked up over its last step (sensor frame). Unlike the waveform's mean
  /// acceleration it does not tilt in a corner: the switch's re-laying tells by it where the
  /// phone sat.
  [[nodiscard]] const std::array<Eigen::Vector3d, 2>& ups() const { return ups_; }
  /// Which foot the last step was (the slot of ups()).
  [[nodiscard]] std::size_t slot() const { return last_slot_; }

 private:
  static constexpr int kWave = RecentSamples::kWave;
  Params params_;
  std::array<Wave, 2> waves_{};             ///< the last two step waveforms
  std::array<Eigen::Vector3d, 2> tilts_{};  ///< their mean gravity directions (sensor frame)
  int wave_count_ = 0;
  Eigen::Vector3d step_up_ = Eigen::Vector3d::Zero();  ///< summed over the step in progress
  std::array<Eigen::Vector3d, 2> ups_{};
  std::size_t last_slot_ = 0;
  bool switching_ = false;
  bool settling_ = false;  ///< switch over, waiting for the new pose to be confirmed
  int settling_steps_ = 0;
  int correlated_steps_ = 0;
  std::array<double, 5> recent_heading_rad_{};  ///< the last steps' headings, oldest first
  int recent_count_ = 0;
  double stand_in_rad_ = 0.0;
  bool have_stand_in_ = false;
};

}  // namespace telltale::fusion
