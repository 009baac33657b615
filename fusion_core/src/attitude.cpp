// Helpers shared by every attitude filter, and the registry by name.
#include "telltale/fusion/attitude.hpp"

#include <cmath>

#include "telltale/fusion/attitude_baselines.hpp"
#include "telltale/fusion/attitude_seed.hpp"
#include "telltale/fusion/attitude_telltale.hpp"

namespace telltale::fusion {

SampleGate gate_sample(const ImuSample& s, bool& started, double& last_t_s, double& dt_s,
                       unsigned& rejected_non_finite, unsigned& rejected_time) {
  dt_s = 0.0;
  if (!std::isfinite(s.t_s) || !s.gyro_body_rad_s.allFinite() || !s.acc_body_m_s2.allFinite()) {
    ++rejected_non_finite;
    return SampleGate::kReject;
  }
  if (!started) {
    started = true;
    last_t_s = s.t_s;
    return SampleGate::kFirst;
  }
  dt_s = s.t_s - last_t_s;
  if (!(dt_s > 0.0)) {
    ++rejected_time;
    return SampleGate::kReject;
  }
  last_t_s = s.t_s;
  return SampleGate::kNext;
}

double fast_atan2(double y, double x) {
  const double ay = std::abs(y);
  const double ax = std::abs(x);
  const bool swap = ay > ax;
  double z = swap ? ax / ay : ay / ax;  // in [0, 1]
  double r = 0.0;
  constexpr double kTanPi12 = 0.26794919243112270;
  constexpr double kSqrt3 = 1.7320508075688772;
  if (z > kTanPi12) {  // atan(z) = pi/6 + atan((sqrt(3) z - 1) / (z + sqrt(3))), |.| <= tan(pi/12)
    z = (kSqrt3 * z - 1.0) / (z + kSqrt3);
    r = M_PI / 6.0;
  }
  const double z2 = z * z;  // |z|^15 / 15 < 2.6e-10 at |z| = tan(pi/12)
  r += z * (1.0 + z2 * (-1.0 / 3.0 +
                        z2 * (1.0 / 5.0 +
                              z2 * (-1.0 / 7.0 +
                                    z2 * (1.0 / 9.0 + z2 * (-1.0 / 11.0 + z2 * (1.0 / 13.0)))))));
  if (swap) r = M_PI / 2.0 - r;
  if (x < 0.0) r = M_PI - r;
  return y < 0.0 ? -r : r;
}

void tilt_from_accel(const Eigen::Vector3d& f, double& heel_rad, double& pitch_rad) {
  // At rest f = g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)).
  heel_rad = std::atan2(f.y(), f.z());
  pitch_rad = std::atan2(f.x(), std::sqrt(f.y() * f.y() + f.z() * f.z()));
}

void euler_rates_from_body(const Eigen::Vector3d& w, double heel_rad, double pitch_rad,
                           double& heel_rate_rad_s, double& pitch_rate_rad_s) {
  const double cp = std::cos(pitch_rad);
  const Eigen::Vector3d up(std::sin(pitch_rad), cp * std::sin(heel_rad), cp * std::cos(heel_rad));
  euler_rates_from_up(w, up, heel_rate_rad_s, pitch_rate_rad_s);
}

void euler_rates_from_up(const Eigen::Vector3d& w, const Eigen::Vector3d& u,
                         double& heel_rate_rad_s, double& pitch_rate_rad_s) {
  // SPEC section 1: pitch is bow-up positive; in FLU a positive rotation about +y (port) puts the
  // bow down, so pitch = -theta of R = Rz(psi) Ry(theta) Rx(phi) and heel = phi. The standard
  // Euler-rate relations dphi = p + (q sin(phi) + r cos(phi)) tan(theta),
  // dtheta = q cos(phi) - r sin(phi) become, with sin(heel) = u_y / c, cos(heel) = u_z / c,
  // tan(pitch) = u_x / c, c = cos(pitch) = hypot(u_y, u_z):
  const double c2 = u.y() * u.y() + u.z() * u.z();
  const double c = std::sqrt(c2);
  heel_rate_rad_s = w.x() - u.x() * (w.y() * u.y() + w.z() * u.z()) / c2;
  pitch_rate_rad_s = (w.z() * u.y() - w.y() * u.z()) / c;
}

double yaw_rate_from_up(const Eigen::Vector3d& w, const Eigen::Vector3d& u) {
  return (w.y() * u.y() + w.z() * u.z()) / (u.y() * u.y() + u.z() * u.z());
}

const std::vector<std::string>& attitude_filter_names() {
  static const std::vector<std::string> names{"telltale", "seed",    "gyro",
                                              "accel",    "average", "kalman-const"};
  return names;
}

std::string attitude_filter_description(std::string_view name) {
  if (name == "telltale")
    return "production: quaternion + inertial-frame low-pass + bias (default)";
  if (name == "seed") return "the paper's time-varying weighted Kalman filter, as published";
  if (name == "gyro") return "gyro-only Euler integration from the first tilt";
  if (name == "accel") return "accelerometer-only tilt";
  if (name == "average") return "fixed-weight average of gyro and accelerometer angles (tau 1 s)";
  if (name == "kalman-const") return "constant-parameter Kalman filter (angle + bias per axis)";
  return {};
}

std::unique_ptr<AttitudeFilter> make_attitude_filter(std::string_view name) {
  if (name == "telltale") return std::make_unique<TelltaleAttitudeFilter>();
  if (name == "seed") return std::make_unique<SeedAttitudeFilter>();
  if (name == "gyro") return std::make_unique<GyroAttitudeFilter>();
  if (name == "accel") return std::make_unique<AccelAttitudeFilter>();
  if (name == "average") return std::make_unique<AverageAttitudeFilter>();
  if (name == "kalman-const") return std::make_unique<ConstKalmanAttitudeFilter>();
  return nullptr;
}

}  // namespace telltale::fusion
