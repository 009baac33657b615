#pragma once
/// \file
/// The one IMU sample type every filter in fusion_core consumes.
/// Frames and signs: body frame FLU (x bow, y port, z up), see idl/README.md.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace telltale::fusion {

/// Standard gravity, m/s^2: what an accelerometer at rest reads (specific force, +g up).
inline constexpr double kStandardGravity_m_s2 = 9.80665;

/// One inertial sample in the body frame (FLU).
struct ImuSample {
  double t_s = 0.0;                                       ///< sample time, seconds (any epoch)
  Eigen::Vector3d gyro_body_rad_s = Eigen::Vector3d::Zero();  ///< body rate, rad/s, right-hand
  Eigen::Vector3d acc_body_m_s2 = Eigen::Vector3d::Zero();    ///< specific force, m/s^2 (+g up at rest)
};

/// The time base of every step detector and dead reckoner: seconds since the first sample, to
/// the microsecond. A sensor's clock ticks on a grid (t0 + n / rate), so durations between
/// samples land exactly on a detector's thresholds (0.2 s is 20 samples at 100 Hz; 0.99 s is
/// 1.5 x 0.66 s). Computed from the caller's time stamps, which side of a threshold such a
/// duration falls on depends on how the stamps round, and so on where time zero is: the same
/// walk stamped from 0 and with Unix time (2^-22 s resolution) counted different steps. From
/// the first sample and rounded to 1 us, every origin gives the same local times, so the same
/// decisions: 1 us is far below any clock tick that matters to gait (1-20 ms) and far above a
/// Unix-time double's rounding (0.12 us until the year 2106). NaN and Inf pass through (the gate
/// refuses them).
class LocalClock {
 public:
  [[nodiscard]] double to_local(double t_s) {
    if (!std::isfinite(t_s)) return t_s;
    if (!started_) {
      started_ = true;
      origin_s_ = t_s;
    }
    return std::round((t_s - origin_s_) * 1e6) / 1e6;
  }
  /// A local time (an event's) on the caller's clock.
  [[nodiscard]] double to_caller(double local_s) const { return origin_s_ + local_s; }

 private:
  double origin_s_ = 0.0;
  bool started_ = false;
};

/// What one IMU can measure, for gate_imu_sample. Defaults: full scale unknown (nothing counts
/// as saturated), gaps over 1 s, gyro required.
struct ImuGateParams {
  double gyro_range_rad_s = std::numeric_limits<double>::infinity();  ///< full scale
  double acc_range_m_s2 = std::numeric_limits<double>::infinity();    ///< full scale
  double saturation_fraction = 0.98;  ///< |reading| >= this * range on an axis -> saturated
  double max_gap_s = 1.0;             ///< a longer step is a gap (samples were dropped)
  /// false: a sample whose gyro is NaN/Inf still passes (gyro_finite = false), for detectors that
  /// can work from the accelerometer alone; the time and the accelerometer are always required.
  bool gyro_required = true;
};

/// What the gate counted, one set per filter or detector (their Diagnostics derive from it).
struct ImuGateCounts {
  unsigned rejected_non_finite = 0;  ///< NaN/Inf in the time, the accelerometer or a required gyro
  unsigned rejected_time = 0;        ///< time not after the last accepted sample
  unsigned gaps = 0;                 ///< accepted after more than max_gap_s
  unsigned gyro_saturated = 0;       ///< accepted with a gyro axis at full scale
  unsigned acc_saturated = 0;        ///< accepted with an accelerometer axis at full scale
};

enum class ImuVerdict { kReject, kFirst, kNext };

/// The gate's verdict on one sample and what the user must know to use it.
struct ImuGateResult {
  ImuVerdict verdict = ImuVerdict::kReject;
  double dt_s = 0.0;  ///< since the last accepted sample (kNext: > 0; otherwise 0)
  bool gyro_finite = false;
  bool gyro_saturated = false;
  bool acc_saturated = false;
  bool gap = false;  ///< dt_s > max_gap_s: the interval is not to be integrated
};

/// The one gate every filter and detector applies to an IMU sample before using it ("should I
/// use this?" apart from "how?"): NaN/Inf in the time, the accelerometer or a required gyro, or a
/// time not after the last accepted one -> kReject; the first accepted sample -> kFirst; later
/// ones -> kNext with dt_s > 0, flagged when saturated or after a gap. Accepting advances
/// last_t_s and sets started (both kept in the caller's State, so a checkpoint carries them);
/// every outcome but a clean sample is counted. Inline: it runs before every update and a call
/// would cost as much as its body.
[[nodiscard]] inline ImuGateResult gate_imu_sample(const ImuSample& sample, const ImuGateParams& p,
                                                   bool& started, double& last_t_s,
                                                   ImuGateCounts& counts) {
  ImuGateResult r;
  // 0 * x is 0 for a finite x and NaN for NaN or Inf: one sum tests several values at once.
  const double acc_zero = 0.0 * sample.t_s + (0.0 * sample.acc_body_m_s2).sum();
  r.gyro_finite = (0.0 * sample.gyro_body_rad_s).sum() == 0.0;
  if (acc_zero != 0.0 || (p.gyro_required && !r.gyro_finite)) {
    ++counts.rejected_non_finite;
    return r;
  }
  if (!started) {
    started = true;
    last_t_s = sample.t_s;
    r.verdict = ImuVerdict::kFirst;
    return r;
  }
  const double dt = sample.t_s - last_t_s;
  if (!(dt > 0.0)) {
    ++counts.rejected_time;
    return r;
  }
  last_t_s = sample.t_s;
  r.verdict = ImuVerdict::kNext;
  r.dt_s = dt;
  r.gyro_saturated = r.gyro_finite && sample.gyro_body_rad_s.cwiseAbs().maxCoeff() >=
                                          p.saturation_fraction * p.gyro_range_rad_s;
  r.acc_saturated =
      sample.acc_body_m_s2.cwiseAbs().maxCoeff() >= p.saturation_fraction * p.acc_range_m_s2;
  r.gap = dt > p.max_gap_s;
  if (r.gyro_saturated | r.acc_saturated | r.gap) [[unlikely]] {
    counts.gyro_saturated += r.gyro_saturated ? 1u : 0u;
    counts.acc_saturated += r.acc_saturated ? 1u : 0u;
    counts.gaps += r.gap ? 1u : 0u;
  }
  return r;
}

/// The rotation of rotation vector `theta` (rad) as a quaternion, of exact angle. Identity for a
/// negligible turn.
[[nodiscard]] inline Eigen::Quaterniond rotation_of(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (!(angle > 1e-12)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

/// The body's rotation over one sample interval from the rates at both ends (trapezoidal rate,
/// exact rotation): q such that v_reference = q v_body_after for a vector expressed in the body
/// frame before (attitude_after = attitude_before * q). A world-fixed vector's coordinates turn
/// by q^-1. Identity for a negligible turn.
[[nodiscard]] inline Eigen::Quaterniond interval_rotation(const Eigen::Vector3d& rate_before,
                                                          const Eigen::Vector3d& rate_after,
                                                          double dt_s) {
  return rotation_of(0.5 * (rate_before + rate_after) * dt_s);
}

/// Two rules of a strapdown integration that follow from how a sample is made (each sample the
/// sensor's reading over the interval that ends at it), shared by the attitude filter and the
/// foot's inertial navigation (docs/attitude.md, the rate table):
///
/// The interval's rotation vector from its gyro increment `dtheta` (rate x dt) and the previous
/// interval's: where the rotation's axis itself turns, increments about different axes do not
/// commute, and the increment alone misses (1/12) dtheta_prev x dtheta (the two-sample coning
/// term, the rate taken as linear across the two intervals). A coning motion makes that error on
/// every interval, in the same sense: it accumulates. Pass zero as `dtheta_prev` after a gap.
[[nodiscard]] inline Eigen::Vector3d coned_rotation_vector(const Eigen::Vector3d& dtheta_prev,
                                                           const Eigen::Vector3d& dtheta) {
  return dtheta + (1.0 / 12.0) * dtheta_prev.cross(dtheta);
}

/// The specific force `f` (body frame) as seen from the attitude at the interval's end, which
/// the gyro's increment `dtheta` has carried the attitude to, turned to the instant the sample
/// describes: half an interval earlier (for point samples too: the rectangle rule carries the
/// attitude half an interval past the rate's instant; a filter delaying both sensors alike moves
/// both instants, not the half interval between them). So R_end * result is the force in the
/// reference frame. Uncorrected, a one-way rotation at w tilts the force by w dt / 2 on every
/// sample, 4 deg at 200 deg/s at 25 Hz. The half rotation a = dtheta / 2 to second order:
/// Rot(-a) f = f + f x a + (a x (a x f)) / 2. (interval_rotation's trapezoidal rate makes the
/// same half-interval correction on the attitude instead, so that it refers to the samples' own
/// instants; the hard-iron fit and the four-pose PDR's up direction pair it with point readings.)
[[nodiscard]] inline Eigen::Vector3d force_at_its_instant(const Eigen::Vector3d& f,
                                                          const Eigen::Vector3d& dtheta) {
  const Eigen::Vector3d a = 0.5 * dtheta;
  const Eigen::Vector3d fa = f.cross(a);
  return f + fa - 0.5 * a.cross(fa);
}

/// The accelerometer's own reading of gravity: |f| averaged over `tau_s` while the sensor is
/// still, so that "|f| near g" means the same on every part (a MEMS accelerometer's scale error
/// of 2-6 % is 0.2-0.6 m/s^2; the IPOL left feet read 10.0-10.5 m/s^2 standing). The foot's INS
/// and the foot's step detector judge stillness against it; each says when it is still.
struct OwnGravity {
  double g_m_s2 = kStandardGravity_m_s2;
  /// A still sample of |f| (m/s^2), dt_s after the last; tau_s <= 0 keeps the standard value.
  void still(double f_norm_m_s2, double dt_s, double tau_s) {
    if (tau_s > 0.0) g_m_s2 += std::min(1.0, dt_s / tau_s) * (f_norm_m_s2 - g_m_s2);
  }
};

}  // namespace telltale::fusion
