#pragma once
/// \file
/// Online magnetometer hard-iron calibration for a hand-carried sensor (the PDR's phone), aided
/// by the gyroscope.
///
/// Model: m = R^T B + b + noise, with B the earth field (unknown, constant in the world), R the
/// sensor's attitude and b the hard-iron offset (constant in the sensor frame). Between two
/// samples j and k the gyro gives the rotation dR = R_k^T R_j, and
///   m_k - b = dR (m_j - b)   =>   (I - dR) b = m_k - dR m_j,
/// three equations linear in b whatever B is. Every sample is paired with the one `lag_s`
/// before it; the normal equations are accumulated (3x3, no heap) with a Gaussian prior
/// b ~ N(0, prior_uT^2) per axis. The information grows only with rotation, so a steady phone
/// calibrates nothing (b stays 0), a turn calibrates the axes perpendicular to the turn axis,
/// and pose switches and an arm swing calibrate the rest.
///
/// Why not the usual sphere fit |m - b| = |B|: with the field magnitude free, a phone that only
/// wobbles a few degrees gives a blob of samples that a tiny sphere fits better than the true
/// one (measured: the fit collapsed to |B| = 1.8 uT in 10 s of walking).
///
/// A pair whose innovation is improbable (gate_chi2: an orientation change the gyro did not
/// see, a magnetic disturbance) is not used. Soft iron
/// (scale/cross-axis) is not modelled.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>

namespace telltale::fusion {

struct HardIronParams {
  double noise_uT = 0.4;           ///< magnetometer white noise per axis, uT
  double gyro_bias_rad_s = 0.005;  ///< uncorrected gyro bias assumed when weighting, rad/s
  double prior_uT = 3.0;           ///< prior standard deviation of each hard-iron component, uT
  double lag_s = 0.5;              ///< time between the two samples of a pair
  double min_rotation_deg = 5.0;   ///< pairs that turned less are not used (see the source)
  double apply_sigma_uT = 1.0;     ///< directions known better than this are applied
  double gate_chi2 = 16.0;         ///< innovation gate (squared Mahalanobis distance, 3 dof)
  std::size_t solve_every = 10;    ///< pairs between two solutions of the 3x3 system
};

class HardIronCalibrator {
 public:
  using Params = HardIronParams;
  static constexpr std::size_t kRing = 128;  ///< samples kept (lag_s at up to ~250 Hz)
  struct State {
    Eigen::Matrix3d info = Eigen::Matrix3d::Zero();  ///< normal matrix incl. the prior
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    Eigen::Vector3d estimate_uT = Eigen::Vector3d::Zero();  ///< least-squares estimate of b
    Eigen::Vector3d offset_uT = Eigen::Vector3d::Zero();    ///< its well-determined part (applied)
    Eigen::Vector3d sigma_uT = Eigen::Vector3d::Zero();     ///< its standard deviation per axis
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();   ///< of the estimate, uT^2
    Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  ///< gyro-integrated
    Eigen::Vector3d last_gyro = Eigen::Vector3d::Zero();
    double last_t_s = 0.0;
    bool started = false;
    std::size_t used = 0;
    std::size_t since_solve = 0;
  };
  struct Diagnostics {
    std::size_t rejected_non_finite = 0;
    std::size_t rejected_gate = 0;   ///< pairs refused as magnetically disturbed
    std::size_t small_rotation = 0;  ///< pairs that turned less than min_rotation_deg
  };
  explicit HardIronCalibrator(Params params = {});
  /// Feeds one sample: time, gyro (rad/s, sensor frame; NaN = no gyro, nothing is learned),
  /// raw magnetometer (uT, sensor frame; NaN skipped).
  void update(double t_s, const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& mag_uT);
  /// The sample with the current hard-iron estimate removed.
  [[nodiscard]] Eigen::Vector3d corrected(const Eigen::Vector3d& mag_uT) const {
    return mag_uT - state_.offset_uT;
  }
  [[nodiscard]] const Eigen::Vector3d& offset_uT() const { return state_.offset_uT; }
  [[nodiscard]] const State& state() const { return state_; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }

 private:
  void solve();
  Params params_;
  State state_;
  Diagnostics diag_;
  struct Entry {
    double t_s = 0.0;
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
  };
  std::array<Entry, kRing> ring_{};
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace telltale::fusion
