#include "telltale/fusion/pdr/track.hpp"

#include <cmath>

namespace telltale::fusion {

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

}  // namespace telltale::fusion
