#pragma once
/// \file
/// Heel and pitch estimation: the common output, the helpers every attitude filter shares, and a
/// registry that builds any filter by name (`fusion_cli attitude --filter NAME`, eval, bench).
///
/// Frames and signs (SPEC section 1): body FLU; the accelerometer reads specific force (+g on z at
/// rest); heel > 0 = starboard down; pitch > 0 = bow up (= -theta of the ZYX sequence).
///
/// Filters in the registry:
///   - `telltale`     TelltaleAttitudeFilter (attitude_telltale.hpp): the production filter,
///   default.
///   - `seed`         SeedAttitudeFilter (attitude_seed.hpp): the paper's filter as published.
///   - `gyro`, `accel`, `average`, `kalman-const` (attitude_baselines.hpp): the paper's yardsticks.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

inline constexpr double kStandardGravity_m_s2 = 9.80665;

/// What every attitude filter reports after each update.
struct AttitudeOutput {
  double heel_rad = 0.0;          ///< + = starboard down
  double pitch_rad = 0.0;         ///< + = bow up
  double heel_rate_rad_s = 0.0;   ///< d(heel)/dt
  double pitch_rate_rad_s = 0.0;  ///< d(pitch)/dt
  /// d(yaw)/dt of the ZYX sequence: + = turning counter-clockwise seen from above (bow to port);
  /// the compass heading rate is its negative. Filled by the production filter (0 from the
  /// others).
  double yaw_rate_rad_s = 0.0;
  double acc_weight = 0.0;  ///< 0..1: how much the accelerometer steered this update
  double quality = 0.0;     ///< 0..1: filter's own confidence (1 = converged, inertial)
  bool valid = false;       ///< false until the first accepted sample
};

/// Common interface so tools can run any filter by name. Concrete filters are `final`, so code
/// that holds the concrete type (the boat node) pays no virtual call.
class AttitudeFilter {
 public:
  virtual ~AttitudeFilter() = default;
  /// Feeds one sample (time strictly increasing; non-uniform spacing allowed). Never throws:
  /// NaN/Inf or non-increasing time are rejected and counted in the filter's Diagnostics.
  virtual void update(const ImuSample& sample) = 0;
  [[nodiscard]] virtual AttitudeOutput output() const = 0;
};

/// Outcome of gate_sample.
enum class SampleGate { kReject, kFirst, kNext };

/// The one gate every attitude filter applies before using a sample: NaN/Inf anywhere, or a time
/// not after the last accepted one -> kReject (counted in the given counter). The first accepted
/// sample -> kFirst (dt_s = 0); later ones -> kNext with dt_s > 0. Accepting advances last_t_s and
/// sets started.
[[nodiscard]] SampleGate gate_sample(const ImuSample& sample, bool& started, double& last_t_s,
                                     double& dt_s, unsigned& rejected_non_finite,
                                     unsigned& rejected_time);

/// Heel and pitch (rad) of the gravity direction seen by an accelerometer at rest:
/// f = g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)) inverted.
void tilt_from_accel(const Eigen::Vector3d& acc_body_m_s2, double& heel_rad, double& pitch_rad);

/// atan2 to within 1e-9 rad, about 4x faster than the C library's (which rounds correctly and
/// costs ~35 ns here): octant reduction, tan(pi/12) range reduction, odd series to z^13.
/// For finite arguments not both zero; used where an update must be cheap (production output).
[[nodiscard]] double fast_atan2(double y, double x);

/// Body rates (FLU, rad/s) -> heel and pitch rates (rad/s) at the given heel and pitch.
/// ZYX Euler kinematics with pitch = -theta (SPEC section 1):
///   dheel/dt  = p + (q sin(heel) + r cos(heel)) tan(theta),  theta = -pitch
///   dpitch/dt = -(q cos(heel) - r sin(heel))
void euler_rates_from_body(const Eigen::Vector3d& gyro_body_rad_s, double heel_rad,
                           double pitch_rad, double& heel_rate_rad_s, double& pitch_rate_rad_s);

/// The same relation from the world's up vector seen in the body,
/// up = (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)), without trigonometry.
void euler_rates_from_up(const Eigen::Vector3d& gyro_body_rad_s, const Eigen::Vector3d& up_body,
                         double& heel_rate_rad_s, double& pitch_rate_rad_s);

/// Yaw rate (rad/s) of the ZYX sequence from body rates and the up vector:
/// dpsi/dt = (q sin(heel) + r cos(heel)) / cos(pitch) = (q u_y + r u_z) / (u_y^2 + u_z^2).
[[nodiscard]] double yaw_rate_from_up(const Eigen::Vector3d& gyro_body_rad_s,
                                      const Eigen::Vector3d& up_body);

/// Names accepted by make_attitude_filter, the default first.
[[nodiscard]] const std::vector<std::string>& attitude_filter_names();
/// One-line description of a filter (for --help).
[[nodiscard]] std::string attitude_filter_description(std::string_view name);
/// Name of the production filter (the default of fusion_cli attitude and of the boat node).
inline constexpr std::string_view kDefaultAttitudeFilter = "telltale";
/// Builds a filter with its default Params; nullptr for an unknown name.
[[nodiscard]] std::unique_ptr<AttitudeFilter> make_attitude_filter(std::string_view name);

}  // namespace telltale::fusion
