// Helpers shared by every attitude filter, and the registry by name.
#include "telltale/fusion/attitude.hpp"

#include <cmath>

#include "telltale/fusion/attitude_baselines.hpp"
#include "telltale/fusion/attitude_seed.hpp"
#include "telltale/fusion/attitude_telltale.hpp"

namespace telltale::fusion {

void tilt_from_accel(const Eigen::Vector3d& f, double& heel_rad, double& pitch_rad) {
  // At rest f = g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)).
  heel_rad = std::atan2(f.y(), f.z());
  pitch_rad = std::atan2(f.x(), std::sqrt(f.y() * f.y() + f.z() * f.z()));
}

void euler_rates_from_body(const Eigen::Vector3d& w, double heel_rad, double pitch_rad,
                           double& heel_rate_rad_s, double& pitch_rate_rad_s) {
  const double cp = std::cos(pitch_rad);
  const Eigen::Vector3d up(std::sin(pitch_rad), cp * std::sin(heel_rad), cp * std::cos(heel_rad));
  AttitudeOutput o;
  output_from_up(w, up, o);
  heel_rate_rad_s = o.heel_rate_rad_s;
  pitch_rate_rad_s = o.pitch_rate_rad_s;
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

std::unique_ptr<AttitudeFilter> make_attitude_filter(std::string_view name,
                                                     const Eigen::Vector3d& lever_arm_m,
                                                     const SensorRanges& ranges) {
  if (name == "telltale") {
    TelltaleAttitudeParams params = with_ranges({}, ranges);
    params.lever_arm_m = lever_arm_m;
    return std::make_unique<TelltaleAttitudeFilter>(params);
  }
  if (name == "seed") return std::make_unique<SeedAttitudeFilter>();
  if (name == "gyro") return std::make_unique<GyroAttitudeFilter>();
  if (name == "accel") return std::make_unique<AccelAttitudeFilter>();
  if (name == "average") return std::make_unique<AverageAttitudeFilter>();
  if (name == "kalman-const") return std::make_unique<ConstKalmanAttitudeFilter>();
  return nullptr;
}

}  // namespace telltale::fusion
