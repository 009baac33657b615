#pragma once
/// \file
/// Which way a body-fixed "forward" axis points, turned about the vertical: the walking
/// direction of a phone held in front (HandheldPdr's WalkingHeading, handheld/walking_yaw.hpp).
///
/// Why not the rate about the vertical, integrated (what it did before): that is
/// the body's rotation about the world's vertical, and the direction a body-fixed axis points in
/// the horizontal plane is not it once the body tilts as it turns. With ZYX angles (yaw psi,
/// pitch theta, roll phi) the vertical component of the body rate is psi' - phi' sin(theta), so
///   psi = integral(omega . up) + integral(sin(theta) dphi):
/// a hand whose roll and pitch swing out of phase traces a loop in (phi, theta) at every step,
/// and each loop adds its area to the axis's direction and not to the integrated rate (the
/// geometric phase of coning). Steps that loop the same way add up: the walk turns where the
/// hand's loops say. The walker points the phone where they walk, so the direction of the axis is
/// what the track needs. (TrunkPdr keeps the rate about the vertical: a trunk sensor's forward axis
/// is its installation's, not known to the pipeline; docs/pdr.md.)
///
/// How: a world-fixed horizontal direction (the reference; its azimuth is arbitrary, only the
/// axis's turns are reported) is carried in the body by the gyro, as any world-fixed vector seen
/// from a turning body (dv/dt = v x omega), and held horizontal and unit against the vertical it
/// is given on every sample (the production attitude filter's up: the gyro turns it, the
/// accelerometer keeps it level). The axis's direction is its angle from the reference about
/// the vertical; the turn reported is that angle's change since the last sample. Where the axis
/// is within 30 deg of the vertical its horizontal direction means nothing (a phone pointing at
/// the floor or the ceiling, not walked with): there the turn is the rate about the vertical,
/// as before.
///
/// A constant error b of the rate (a gyro bias) turns the axis by b . up per second, to first
/// order, like the integrated rate: relay_track's re-laying with another bias holds for both.
///
/// No heap; a copyable value.

#include <Eigen/Core>

namespace telltale::fusion {

class ForwardAxisYaw {
 public:
  /// `forward_body`: the axis, in the sensor's frame (any length but zero).
  explicit ForwardAxisYaw(const Eigen::Vector3d& forward_body);
  /// One sample: the body rate (rad/s, bias taken off) over the dt_s before it, and the vertical
  /// in the body (unit) at its end. Returns the axis's turn about the vertical over the sample
  /// (rad, counter-clockwise seen from above). The first sample, and the first after restart(),
  /// only sets the reference (level with `up`) and returns 0.
  double update(const Eigen::Vector3d& rate_rad_s, double dt_s, const Eigen::Vector3d& up);
  /// Forget the orientation (a gap: the rate over it is unknown); the next update starts level.
  void restart() { started_ = false; }

 private:
  /// The axis's components along the reference and along up x reference (its horizontal part),
  /// and whether it has a direction (more than 30 deg from the vertical).
  void horizontal(const Eigen::Vector3d& up, Eigen::Vector2d& h, bool& usable) const;
  Eigen::Vector3d forward_;
  double forward_norm2_;
  Eigen::Vector3d ref_ = Eigen::Vector3d::UnitX();  ///< the world-fixed horizontal, in the body
  Eigen::Vector2d h_prev_ = Eigen::Vector2d::Zero();
  bool usable_prev_ = false;
  bool started_ = false;
};

}  // namespace telltale::fusion
