#include "telltale/fusion/pdr/track.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/pdr/pose_classifier.hpp"
#include "telltale/fusion/pdr/walking_heading.hpp"

namespace telltale::fusion {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

}  // namespace

void Track::begin_step() {
  have_step_sens_ = sens_n_ > 0;
  step_sens_ = have_step_sens_ ? Eigen::Vector3d(sens_sum_ / sens_n_) : Eigen::Vector3d::Zero();
  sens_sum_.setZero();
  sens_n_ = 0;
}

void Track::lay(double length_m, double heading_rad, bool in_pose,
                const Eigen::Vector3d& offset_uT) {
  const double laid_m = length_m + pending_m_;
  x_m_ += laid_m * std::sin(heading_rad);
  y_m_ += laid_m * std::cos(heading_rad);
  pending_m_ = 0.0;
  if (in_pose) {
    pose_disp_ += laid_m * Eigen::Vector2d(std::sin(heading_rad), std::cos(heading_rad));
    ++pose_steps_;
    if (revise_offset_ && have_step_sens_) {
      // d(east, north)/dheading times dheading/doffset: how this step moves per uT of offset.
      const Eigen::Matrix<double, 2, 3> a =
          laid_m * Eigen::Vector2d(std::cos(heading_rad), -std::sin(heading_rad)) *
          step_sens_.transpose();
      mag_a_ += a;
      mag_c_ += a * offset_uT;
    }
  }
  if (params_.revise) revise_offset(offset_uT);
}

double Track::turn_pose(double corr_rad) {
  // The pose's steps were laid with heading - pose_corr_rad_; with the better estimate they turn
  // about the point where the pose began (headings clockwise, so east/north turn the other way).
  const double d = corr_rad - pose_corr_rad_;
  if (d == 0.0) return 0.0;
  const double c = std::cos(d), sn = std::sin(d);
  const Eigen::Vector2d turned(pose_disp_.x() * c - pose_disp_.y() * sn,
                               pose_disp_.y() * c + pose_disp_.x() * sn);
  x_m_ += turned.x() - pose_disp_.x();
  y_m_ += turned.y() - pose_disp_.y();
  pose_disp_ = turned;
  pose_corr_rad_ = corr_rad;
  return d;
}

void Track::revise_offset(const Eigen::Vector3d& offset_uT) {
  // First order in the heading change (a few degrees at most: a 1 uT offset in a 20 uT
  // horizontal field is 3 deg).
  const Eigen::Vector2d corr = mag_a_ * offset_uT - mag_c_;
  x_m_ += corr.x() - mag_applied_.x();
  y_m_ += corr.y() - mag_applied_.y();
  mag_applied_ = corr;
}

void Track::new_pose() {
  pose_disp_.setZero();
  pose_corr_rad_ = 0.0;
  pose_steps_ = 0;
}

// --- pose switches ------------------------------------------------------------------------------
std::size_t SwitchRelay::begin(const std::array<Eigen::Vector3d, 2>& ups) {
  count_ = 0;
  const std::size_t back = last_count_;
  ups_before_switch_ = back > 0 ? last_ups_before_[kLookback - back] : ups;
  for (std::size_t i = kLookback - back; i < kLookback; ++i) steps_[count_++] = last_[i];
  last_count_ = 0;
  return back;
}

void SwitchRelay::keep_last(const SwitchStep& laid,
                            const std::array<Eigen::Vector3d, 2>& ups_before) {
  for (std::size_t i = 0; i + 1 < kLookback; ++i) {
    last_[i] = last_[i + 1];
    last_ups_before_[i] = last_ups_before_[i + 1];
  }
  last_.back() = laid;
  last_ups_before_.back() = ups_before;
  last_count_ = std::min(last_count_ + 1, kLookback);
}

void SwitchRelay::turn_last(double d_rad, std::size_t pose_steps) {
  // Steps a later switch may re-lay must know the heading they now have.
  const std::size_t n = std::min(last_count_, pose_steps);
  for (std::size_t i = kLookback - n; i < kLookback; ++i)
    last_[i].laid_rad = wrap_2pi(last_[i].laid_rad - d_rad);
}

void SwitchRelay::relay(Track& track, const std::array<Eigen::Vector3d, 2>& ups,
                        std::optional<double> stand_in_rad, std::optional<double> heading_after,
                        PhonePose pose, double tilt_deg) {
  // At each step of a pose switch and at the first after it (our addition to seed 003). While
  // the phone was moved, the steps were laid with the heading from before the switch; with the
  // pose the classifier sees (at the end, the confirmed one), each switch step is given the
  // heading it really had:
  //  - steps whose up direction (sensor frame, gyro-tracked: a corner's centripetal
  //    acceleration does not tilt it) already matches the new steady one (same foot: an arm
  //    swing alternates): the phone was in its new place, so the walking
  //    direction is the new pose's forward axis, from that step's field and gyro-tracked up
  //    (a turn during the settling steps is then measured, not interpolated);
  //  - steps still in the old orientation: the heading filter's heading in the old frame;
  //  - the steps of the movement itself: interpolated between those.
  const double tol = std::cos(tilt_deg * M_PI / 180.0);
  const std::size_t axis = pose_rotation(pose)(0, 0) > 0.5 ? 0 : 1;
  const std::size_t n = count_;
  std::array<double, kMaxSteps> h{};
  std::array<bool, kMaxSteps> known{}, in_new{};
  bool moved = false;
  for (std::size_t k = 0; k < n; ++k) {
    const SwitchStep& r = steps_[k];
    known[k] = false;
    if (r.up.dot(ups[r.slot]) > tol) {
      const Eigen::Vector2d& v = r.axis_sum[axis];
      if (v.norm() > 1e-9) {
        h[k] = wrap_2pi(std::atan2(v.x(), v.y()));
        known[k] = in_new[k] = true;
      }
      moved = true;
    } else if (!moved && r.up.dot(ups_before_switch_[r.slot]) > tol) {
      h[k] = r.old_frame_rad;
      known[k] = true;
    } else {
      moved = true;
    }
  }
  // Interpolate the unknown ones between the nearest known headings (the replacement heading
  // before the first, the heading after the switch after the last).
  double before = stand_in_rad ? *stand_in_rad : steps_[0].laid_rad;
  std::size_t before_k = 0;
  bool have_before_k = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (known[k]) {
      before = h[k];
      before_k = k;
      have_before_k = true;
      continue;
    }
    std::size_t next = k;
    while (next < n && !known[next]) ++next;
    const double after = next < n ? h[next] : heading_after ? *heading_after : before;
    const double span =
        static_cast<double>(next) - (have_before_k ? static_cast<double>(before_k) : -1.0);
    const double pos =
        static_cast<double>(k) - (have_before_k ? static_cast<double>(before_k) : -1.0);
    h[k] = before + std::remainder(after - before, kTwoPi) * pos / span;
  }
  for (std::size_t k = 0; k < n; ++k) {
    SwitchStep& r = steps_[k];
    track.shift(r.length_m * (std::sin(h[k]) - std::sin(r.laid_rad)),
                r.length_m * (std::cos(h[k]) - std::cos(r.laid_rad)));
    r.laid_rad = h[k];  // a later re-laying moves it from here
    // Steps walked in the new pose turn with its walking-direction correction once that is
    // learnt (revise_pose_yaw), like the pose's later steps: they were laid with its raw axis.
    if (heading_after && in_new[k])
      track.add_to_pose(r.length_m * Eigen::Vector2d(std::sin(h[k]), std::cos(h[k])));
  }
}

}  // namespace telltale::fusion
