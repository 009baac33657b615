#pragma once
/// \file
/// Gait simulator with ground truth: a person walks or runs along a path carrying a foot-mounted
/// IMU (toe, like the JY901B of seed 004) or a phone in one of the four poses of seed 003.
///
/// Physics (walking frame W: x forward along the path, y left, z up; world ENU, heading clockwise
/// from north):
/// - walking: inverted-pendulum centre of mass, lowest at heel strike, so the vertical specific
///   force peaks at heel strike, `z = -A cos(2 pi phi)`; forward speed highest at double support
///   (`v = L/T (1 + e cos 2 pi phi)`); lateral sway at half the step frequency; a heel-strike
///   transient; trunk yaw/roll at stride frequency, pitch at step frequency;
/// - jog/run: spring-mass bounce, vertical force a half sine over the contact fraction of each
///   step (mean g), free fall in flight;
/// - foot (toe sensor): stance with foot slap after heel strike, heel-off rotation about the toe
///   (toe-down pitch up to ~35 deg), swing with minimum-jerk forward travel of one stride, toe
///   clearance, toe-up before the next heel strike; heel-strike and foot-flat impacts;
/// - phone: hand-held (arm-damped trunk motion + hand tremor), phone call (head-stabilised),
///   shirt pocket (rigid to the trunk), arm swing (pendulum at stride frequency from the shoulder,
///   tangential + centripetal acceleration and a large rotation). Sensor axes per pose follow the
///   rotation matrices of seed 003 (v_walking = M_pose v_sensor), with a per-person misalignment.
/// - pose switches: the phone is carried from one pose to the next in `switch_s`, its orientation
///   slerped (the gyro sees the rotation, the accelerometer the turning gravity).
///
/// Sensor error model (documented here, independent of any other simulator): per run, constant
/// biases drawn once (accelerometer N(0, 0.05 m/s^2) per axis, gyro N(0, 0.003 rad/s) per axis,
/// magnetometer hard-iron residual N(0, 1 uT)); per sample white noise (0.04 m/s^2, 0.006 rad/s,
/// 0.4 uT); clipping at +-16 g and +-2000 deg/s (JY901B ranges). Earth field ENU (0, 20, -44) uT.
///
/// Deterministic: the same scenario, person and seed give the same samples on every platform
/// (mt19937_64 with our own uniform/normal transforms).

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/phone_pose.hpp"

namespace telltale::fusion::sim {

enum class Gait { kSlowWalk, kWalk, kFastWalk, kJog, kRun };
inline constexpr int kGaitCount = 5;
using fusion::kPoseCount;
using fusion::PhonePose;
enum class SensorSite { kFoot, kPhone };

[[nodiscard]] std::string_view gait_name(
    Gait g);  ///< "slow-walk", "walk", "fast-walk", "jog", "run"
[[nodiscard]] std::optional<Gait> gait_from_name(std::string_view name);
[[nodiscard]] std::string_view pose_name(
    PhonePose p);  ///< "hand-held", "call", "pocket", "arm-swing"
[[nodiscard]] std::optional<PhonePose> pose_from_name(std::string_view name);

/// Portable deterministic random numbers.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double normal();  ///< N(0, 1), Box-Muller

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// One simulated person: height and personal deviations from the population gait table.
struct Person {
  double height_m = 1.75;
  double cadence_scale = 1.0;     ///< multiplies the population cadence
  double step_scale = 1.0;        ///< multiplies the population step length / height ratio
  double bounce_scale = 1.0;      ///< vertical centre-of-mass excursion
  double arm_swing_deg = 30.0;    ///< amplitude of the arm pendulum (arm-swing pose)
  double toe_off_deg = 35.0;      ///< peak toe-down pitch at toe-off
  double heel_strike_deg = 20.0;  ///< toe-up pitch at heel strike
  /// The foot's turns off its pitch (a real foot's swing turns about its long axis and the
  /// vertical at 0.3-1 x its pitch rate, IPOL feet): inversion at mid-swing (deg), the toes'
  /// swing in and out at mid-swing (deg), and the inversion it lands with, everted flat by foot
  /// flat (deg).
  double swing_roll_deg = 8.0;
  double swing_yaw_deg = 6.0;
  double strike_roll_deg = 5.0;
  double mount_yaw_deg[kPoseCount] = {0, 0, 0, 0};   ///< phone yaw misalignment per pose
  double mount_tilt_deg[kPoseCount] = {0, 0, 0, 0};  ///< phone tilt misalignment per pose
};
/// Draws a person: height uniform in [1.55, 1.95] m, cadence and step scales +-8 %, etc.
[[nodiscard]] Person random_person(std::uint64_t seed);

/// Which step of a walk: the first from standing, one within the walk, or the closing heel
/// strike after its last step.
enum class WalkStep { kFirst, kWithin, kClosing };

/// The trunk's vertical acceleration (m/s^2, up) t_in_s into a walking step of `period_s` and
/// `length_m`, for a person of `height_m` and `bounce_scale`; for kClosing, t_in_s after the
/// closing heel strike. An inverted pendulum: the centre of mass drops over half a step, lowest
/// at the heel strike, whose loading lifts it again (with the impact's 12 Hz ringing). A walk
/// starts and ends as a real one does (IPOL lower-back trials, docs/steps.md): the first step
/// begins with no heel strike, only the push of the swing leg's toe-off, which lifts the trunk by
/// a fraction of a loading (0.25; 0.07-0.39 of the walk's loading peaks on the real trials) and
/// returns it; the closing heel strike's loading brings the trunk to rest over a quarter step.
/// The one walk of the simulators: gait_sim's walker and the phone walk (phone_walk.hpp).
[[nodiscard]] double walking_trunk_up(WalkStep step, double t_in_s, double period_s,
                                      double length_m, double height_m, double bounce_scale);

/// Population gait table scaled for a person: step frequency (Hz) and step length (m).
[[nodiscard]] double nominal_step_hz(Gait g, const Person& p);
[[nodiscard]] double nominal_step_length_m(Gait g, const Person& p);

/// A span of time with one gait and one phone pose.
struct GaitSegment {
  Gait gait = Gait::kWalk;
  PhonePose pose = PhonePose::kHandHeld;
  double duration_s = 60.0;
};

/// A straight leg followed by a turn (rounded with `corner_radius_m`), degrees, + = right turn.
struct PathLeg {
  double length_m = 100.0;
  double turn_deg = 0.0;
};

struct SensorErrors {
  double acc_noise_m_s2 = 0.04;
  double acc_bias_m_s2 = 0.05;
  double gyro_noise_rad_s = 0.006;
  double gyro_bias_rad_s = 0.003;
  double mag_noise_uT = 0.4;
  double mag_bias_uT = 1.0;
  double acc_range_m_s2 = 16.0 * kStandardGravity_m_s2;
  double gyro_range_rad_s = 2000.0 * M_PI / 180.0;
};

struct GaitScenario {
  std::string name;
  SensorSite site = SensorSite::kFoot;
  double rate_hz = 100.0;
  double start_heading_deg = 0.0;
  double standing_s = 2.0;  ///< standing still before the walk starts (and after it ends)
  /// The gait/pose schedule; the last segment is held while a closed path is not finished.
  std::vector<GaitSegment> segments;
  /// Path legs; empty = a 400 m stadium track. With `closed`, the walk ends at the path's end.
  std::vector<PathLeg> path;
  bool closed = false;
  double corner_radius_m = 0.6;
  double switch_s = 1.5;  ///< duration of a pose switch
  SensorErrors errors;
};

/// One sample with its truth.
struct GaitSample {
  ImuSample imu;
  Eigen::Vector3d mag_uT = Eigen::Vector3d::Zero();  ///< magnetometer, sensor frame, uT
  double x_m = 0.0;                                  ///< truth position east, m
  double y_m = 0.0;                                  ///< truth position north, m
  double heading_deg = 0.0;  ///< truth walking direction, clockwise from north
  double distance_m = 0.0;   ///< truth distance walked
  Gait gait = Gait::kWalk;
  PhonePose pose = PhonePose::kHandHeld;
  bool switching = false;      ///< a pose switch is in progress
  int steps = 0;               ///< truth steps (both feet) so far (heel strikes)
  int foot_steps = 0;          ///< truth heel strikes of the instrumented (left) foot so far
  double step_hz = 0.0;        ///< truth step frequency of the current step
  double step_length_m = 0.0;  ///< truth length of the current step
};

struct GaitRun {
  std::vector<GaitSample> samples;
  std::vector<double> step_times_s;       ///< every heel strike
  std::vector<double> foot_step_times_s;  ///< heel strikes of the instrumented foot
  double distance_m = 0.0;
};

/// Runs a scenario for a person with a noise seed.
[[nodiscard]] GaitRun simulate_gait(const GaitScenario& scenario, const Person& person,
                                    std::uint64_t seed);

/// Scenarios by name: "foot-GAIT", "body-GAIT" (phone in the shirt pocket), "phone-POSE-GAIT",
/// "foot-mixed" / "body-mixed" / "phone-POSE-mixed" (every gait in turn, 30 s each),
/// "phone-switch" (walk, the four poses in turn), "loop" (closed rectangular walk with pose
/// switches; the seed picks its size and switch times). GAIT: slow-walk, walk, fast-walk, jog,
/// run. nullopt for an unknown name.
[[nodiscard]] std::optional<GaitScenario> make_gait_scenario(std::string_view name,
                                                             std::uint64_t seed);
[[nodiscard]] std::vector<std::string> gait_scenario_examples();
/// A phone carried in one pose at one gait along a straight 1 km line for `duration_s` (the
/// calibration walks of the step-length model and the arm-swing step tests).
[[nodiscard]] GaitScenario straight_phone_walk(Gait gait, PhonePose pose, double duration_s);

}  // namespace telltale::fusion::sim
