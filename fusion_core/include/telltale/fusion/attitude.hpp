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

#include <Eigen/Core>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

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
  /// every filter passes the sample through gate_imu_sample (imu_sample.hpp) first, so NaN/Inf
  /// or non-increasing time are rejected and counted in the filter's Diagnostics.
  virtual void update(const ImuSample& sample) = 0;
  [[nodiscard]] virtual AttitudeOutput output() const = 0;
  /// The boat's speed (m/s, forward, horizontal), its rate of change (m/s^2) and the rate of its
  /// course over ground (rad/s, clockwise +, as the compass turns), held for the updates that
  /// follow until the next call; NaN speed = unknown (the default), NaN speed rate = 0, NaN
  /// course rate = unknown. Filters that cannot use them ignore them (the default); see
  /// TelltaleAttitudeFilter::set_speed.
  virtual void set_speed(double /*speed_m_s*/, double /*speed_rate_m_s2*/,
                         double /*cog_rate_rad_s*/) {}
};

/// Heel and pitch (rad) of the gravity direction seen by an accelerometer at rest:
/// f = g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)) inverted.
void tilt_from_accel(const Eigen::Vector3d& acc_body_m_s2, double& heel_rad, double& pitch_rad);

/// A unit vector perpendicular to the unit vector u (a horizontal direction when u is up; which
/// one does not matter to the callers: the production filter's motion update measures in any
/// horizontal basis, ForwardAxisYaw reports only turns from its reference). Always inlined:
/// with three callers in the filter's update the compiler made it a call, 27 instructions per
/// update (callgrind). The normalisation is Eigen's normalized() written out (the same squared
/// norm, square root and division, so the same bits): GCC kept that one an out-of-line call.
[[gnu::always_inline]] inline Eigen::Vector3d perpendicular(const Eigen::Vector3d& u) {
  const Eigen::Vector3d a =
      std::abs(u.x()) < 0.8 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d v = a - a.dot(u) * u;
  const double n2 = v.squaredNorm();
  return n2 > 0.0 ? Eigen::Vector3d(v / std::sqrt(n2)) : v;
}

/// atan2 to within 1e-9 rad, 2-4x faster than the C library's (which rounds correctly): one
/// division and no data-dependent branch. For finite arguments not both zero; used where an
/// update must be cheap (the production filter's output). Inline: the production update is one
/// long dependency chain and a call would spill its registers.
[[nodiscard]] inline double fast_atan2(double y, double x) {
  // With t = min/max of |y|, |x| in [0, 1], atan(t) = pi/6 + atan((sqrt(3) t - 1) / (t + sqrt(3)))
  // folds t > tan(pi/12) into |z| <= tan(pi/12); multiplied through by max(|y|, |x|) it stays a
  // single quotient.
  constexpr double kTanPi12 = 0.26794919243112270;
  constexpr double kSqrt3 = 1.7320508075688772;
  const double ay = y < 0.0 ? -y : y;
  const double ax = x < 0.0 ? -x : x;
  const bool swap = ay > ax;
  const double lo = swap ? ax : ay;
  const double hi = swap ? ay : ax;
  const bool fold = lo > kTanPi12 * hi;
  const double z = (fold ? kSqrt3 * lo - hi : lo) / (fold ? lo + kSqrt3 * hi : hi);
  // atan(z) = z (1 - z^2/3 + ... + z^12/13), |z|^15 / 15 < 2.6e-10 at tan(pi/12); Estrin's
  // scheme (depth 3 instead of Horner's 6).
  const double z2 = z * z;
  const double z4 = z2 * z2;
  const double z8 = z4 * z4;
  double r = z * ((1.0 - z2 * (1.0 / 3.0)) + z4 * (1.0 / 5.0 - z2 * (1.0 / 7.0)) +
                  z8 * ((1.0 / 9.0 - z2 * (1.0 / 11.0)) + z4 * (1.0 / 13.0)));
  r += fold ? M_PI / 6.0 : 0.0;
  r = swap ? M_PI / 2.0 - r : r;
  r = x < 0.0 ? M_PI - r : r;
  return y < 0.0 ? -r : r;
}

/// fast_atan2(y0, x0) and fast_atan2(y1, x1) at once: with SSE2 the two lanes of one register take
/// the same approximation (the same results to rounding, ~1e-16 rad) for about half the
/// instructions of two calls. The production output needs heel and pitch on every read, and it
/// waits for this: the octant bookkeeping is arranged off the path from the division to the result.
inline void fast_atan2_pair(double y0, double x0, double y1, double x1, double& r0, double& r1) {
#if defined(__SSE2__)
  const auto select = [](__m128d mask, __m128d a, __m128d b) {  // mask ? a : b, lane by lane
    return _mm_or_pd(_mm_and_pd(mask, a), _mm_andnot_pd(mask, b));
  };
  const auto c = [](double v) { return _mm_set1_pd(v); };
  const __m128d y = _mm_set_pd(y1, y0);
  const __m128d x = _mm_set_pd(x1, x0);
  const __m128d sign = c(-0.0);
  const __m128d ay = _mm_andnot_pd(sign, y);
  const __m128d ax = _mm_andnot_pd(sign, x);
  const __m128d swap = _mm_cmpgt_pd(ay, ax);
  const __m128d lo = _mm_min_pd(ay, ax);  // = select(swap, ax, ay) for numbers: one operation
  const __m128d hi = _mm_max_pd(ay, ax);
  constexpr double kTanPi12 = 0.26794919243112270;
  constexpr double kSqrt3 = 1.7320508075688772;
  const __m128d fold = _mm_cmpgt_pd(lo, _mm_mul_pd(c(kTanPi12), hi));
  const __m128d z = _mm_div_pd(select(fold, _mm_sub_pd(_mm_mul_pd(c(kSqrt3), lo), hi), lo),
                               select(fold, _mm_add_pd(lo, _mm_mul_pd(c(kSqrt3), hi)), hi));
  const __m128d z2 = _mm_mul_pd(z, z);
  const __m128d z4 = _mm_mul_pd(z2, z2);
  const __m128d z8 = _mm_mul_pd(z4, z4);
  const __m128d p0 = _mm_sub_pd(c(1.0), _mm_mul_pd(z2, c(1.0 / 3.0)));
  const __m128d p1 = _mm_mul_pd(z4, _mm_sub_pd(c(1.0 / 5.0), _mm_mul_pd(z2, c(1.0 / 7.0))));
  const __m128d p2 =
      _mm_mul_pd(z8, _mm_add_pd(_mm_sub_pd(c(1.0 / 9.0), _mm_mul_pd(z2, c(1.0 / 11.0))),
                                _mm_mul_pd(z4, c(1.0 / 13.0))));
  const __m128d a = _mm_mul_pd(z, _mm_add_pd(_mm_add_pd(p0, p1), p2));
  // The octant steps r += pi/6 (fold), r = pi/2 - r (swap), r = pi - r (x < 0), r = -r (y < 0)
  // are each r -> +-r + offset, so together they are one sign flip of a plus one offset, both
  // known from the masks long before a is: the result is one xor and one addition after a.
  const __m128d xneg = _mm_cmplt_pd(x, _mm_setzero_pd());
  const __m128d yneg = _mm_and_pd(sign, y);  // the sign bit of y
  const __m128d flip = _mm_xor_pd(_mm_and_pd(sign, _mm_xor_pd(swap, xneg)), yneg);
  __m128d off = _mm_and_pd(fold, c(M_PI / 6.0));
  off = _mm_add_pd(_mm_xor_pd(off, _mm_and_pd(sign, swap)), _mm_and_pd(swap, c(M_PI / 2.0)));
  off = _mm_add_pd(_mm_xor_pd(off, _mm_and_pd(sign, xneg)), _mm_and_pd(xneg, c(M_PI)));
  off = _mm_xor_pd(off, yneg);
  const __m128d r = _mm_add_pd(_mm_xor_pd(a, flip), off);
  r0 = _mm_cvtsd_f64(r);
  r1 = _mm_cvtsd_f64(_mm_unpackhi_pd(r, r));
#else
  r0 = fast_atan2(y0, x0);
  r1 = fast_atan2(y1, x1);
#endif
}

/// Body rates (FLU, rad/s) -> heel and pitch rates (rad/s) at the given heel and pitch.
/// ZYX Euler kinematics with pitch = -theta (SPEC section 1):
///   dheel/dt  = p + (q sin(heel) + r cos(heel)) tan(theta),  theta = -pitch
///   dpitch/dt = -(q cos(heel) - r sin(heel))
void euler_rates_from_body(const Eigen::Vector3d& gyro_body_rad_s, double heel_rad,
                           double pitch_rad, double& heel_rate_rad_s, double& pitch_rate_rad_s);

/// Heel, pitch and their rates, and the yaw rate, from body rates and the world's up vector seen
/// in the body, up = (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)) (unit), without
/// trigonometry beyond two fast_atan2: one square root and one division in all. Fills those five
/// fields of `o` and leaves the others. The rates are the ZYX Euler kinematics of
/// euler_rates_from_body, with sin(heel) = u_y / c, cos(heel) = u_z / c, tan(pitch) = u_x / c,
/// c = cos(pitch) = hypot(u_y, u_z):
///   dheel/dt  = p - u_x (q u_y + r u_z) / c^2
///   dpitch/dt = (r u_y - q u_z) / c
///   dyaw/dt   = (q u_y + r u_z) / c^2   (ZYX yaw: + = bow to port)
inline void output_from_up(const Eigen::Vector3d& gyro_body_rad_s, const Eigen::Vector3d& up_body,
                           AttitudeOutput& o) {
  const Eigen::Vector3d& w = gyro_body_rad_s;
  const Eigen::Vector3d& u = up_body;
  const double c2 = u.y() * u.y() + u.z() * u.z();
  const double c = std::sqrt(c2);
  const double inv_c2 = 1.0 / c2;
  const double yaw_rate = (w.y() * u.y() + w.z() * u.z()) * inv_c2;
  fast_atan2_pair(u.y(), u.z(), u.x(), c, o.heel_rad, o.pitch_rad);
  o.heel_rate_rad_s = w.x() - u.x() * yaw_rate;
  o.pitch_rate_rad_s = (w.z() * u.y() - w.y() * u.z()) * c * inv_c2;
  o.yaw_rate_rad_s = yaw_rate;
}

/// Names accepted by make_attitude_filter, the default first.
[[nodiscard]] const std::vector<std::string>& attitude_filter_names();
/// One-line description of a filter (for --help).
[[nodiscard]] std::string attitude_filter_description(std::string_view name);
/// Name of the production filter (the default of fusion_cli attitude and of the boat node).
inline constexpr std::string_view kDefaultAttitudeFilter = "telltale";
/// A sensor's full scales (rad/s, m/s^2): a reading near one is clipped, not the motion.
/// Infinite: not known.
struct SensorRanges {
  double gyro_rad_s = std::numeric_limits<double>::infinity();
  double acc_m_s2 = std::numeric_limits<double>::infinity();
};
/// Builds a filter with its default Params; nullptr for an unknown name. `lever_arm_m` is the
/// installation's sensor offset from the boat's centre (TelltaleAttitudeParams::lever_arm_m);
/// `ranges` the sensor's full scales where known (the production filter's defaults are the
/// boat instrument's, 250 deg/s and 2 g). The baselines model neither and ignore both.
[[nodiscard]] std::unique_ptr<AttitudeFilter> make_attitude_filter(
    std::string_view name, const Eigen::Vector3d& lever_arm_m = Eigen::Vector3d::Zero(),
    const SensorRanges& ranges = {});

}  // namespace telltale::fusion
