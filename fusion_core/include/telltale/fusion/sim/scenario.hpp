#pragma once
/// \file
/// Streaming IMU scenarios with ground truth (used by `fusion_cli simulate`, the tests, eval, and
/// the boat node's `--source sim:SCENARIO`; plain `--source sim` runs `race` live and endlessly,
/// on the same course as its simulated receiver: race.hpp).
///
///   auto sc = sim::make_scenario("dinghy", seed, 25.0, 0.0);   // 0 = endless
///   ImuSample imu; sim::AttitudeTruth truth;
///   while (sc->next(imu, truth)) filter.update(imu);
///
/// Scenarios (sim::scenario_names()):
///   pendulum-{heel,pitch}-{5,10,15,20,25,30}: the paper's gravity pendulum, 0.95 m, damping ratio
///     0.018, held at the release angle for 5 s then released; instrument at the bob, mounted to
///     swing in heel or in pitch. Dynamics by RK4 (the bob's accelerometer reads almost no tilt in
///     the swing plane, as it physically must).
///   turntable: fixed heel -17.5 deg, pitch 7.5 deg, 0.2 m off-centre, yaw rate 90 sin(2 pi t/40)
///     deg/s after 5 s still.
///   desk: hand-shaken on a desk (+-20 deg, a few m/s^2) with a knock every 2..6 s (2 mm, 8 ms:
///     ~10 g, the 2 g accelerometer saturates), after 5 s still.
///   dinghy: a Laser upwind in a chop: 10 s still ashore, then sailing at 2.5 m/s, tacking every
///     ~40 s (90 deg in ~4 s, heel flips +-12 deg), gusts (+3..8 deg of heel), waves (heave, surge,
///     sway ~1.5 m/s^2; roll +-3 deg, pitch +-5 deg), instrument on the bow (1.5 m ahead of the
///     CG).
///   yaw-{10,30,60,90,120}: the instrument at heel -17.5 deg, pitch 7.5 deg ON the axis of a
///     turntable, 5 s still, then spun up (~2 s) to a steady yaw rate of that many deg/s; scored
///     from the end of the rest.
///   underway-5, underway-15: the dinghy joined 100..120 s into its script (sailing in waves,
///     instrument on the bow, no rest before the first sample), 60 s; scored from 5 s or 15 s.
///   race: the boat of the windward-leeward race (course.hpp, the same seed) as a rigid body:
///     heading, speed and heel (to leeward, flipping at each tack and gybe) are the course's,
///     smoothed over ~0.14 s (race.hpp); the dinghy's waves and 1 deg trim, the instrument on its
///     bow. Under way from the first sample (no rest); 600 s (a beat with its tacks, the
///     windward mark, the run with its gybes); scored from 15 s.
/// The dinghy, underway and race scenarios also have a GNSS receiver (gnss_fix()): speed
/// and course over ground of the boat's centre at ScenarioOptions::gnss_rate_hz, with noise and
/// latency.
/// Sensor: ImuErrorModel with the L3G4200D/LSM303DLH defaults of imu_errors.hpp.

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/sim/imu_errors.hpp"
#include "telltale/fusion/sim/motion.hpp"

namespace telltale::fusion::sim {

/// The truth of one sample (the pose of the body at the sample's time).
struct AttitudeTruth {
  double t_s = 0.0;
  double heel_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;  ///< counter-clockwise from world x (ENU), not a compass heading
  double heel_rate_rad_s = 0.0;
  double pitch_rate_rad_s = 0.0;
  /// What an error-free sensor reads: the mean body rate and specific force (at the sensor) over
  /// the sample interval (the sensors' decimation filter); instantaneous for the first sample.
  Eigen::Vector3d gyro_true_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_true_m_s2 = Eigen::Vector3d::Zero();
};

/// Timing and sensor options of a run.
struct ScenarioOptions {
  ImuErrorParams errors{};
  double jitter_s = 0.0;          ///< uniform +- jitter on every time stamp (< 0.5 / rate)
  double drop_probability = 0.0;  ///< chance that a sample is lost (non-uniform sampling)
  double g_m_s2 = kStandardGravity_m_s2;
  /// The GNSS receiver of the scenarios that have one: epochs per second, the white noise of
  /// its velocity, east and north (a u-blox M8's 0.05 m/s), and the time from its epoch to the
  /// fix's arrival beside the IMU samples (navigation solution and transfer, ~0.1 s).
  double gnss_rate_hz = 5.0;
  double gnss_speed_sigma_m_s = 0.05;
  double gnss_latency_s = 0.1;
};

/// A GNSS fix as it reaches the boat: the IMU sample time it arrived with, the speed and course
/// over ground of the trajectory's origin at the epoch (from its horizontal velocity plus white
/// noise of gnss_speed_sigma_m_s on each of east and north).
struct GnssSpeedFix {
  double t_s = 0.0;
  double sog_m_s = 0.0;
  double cog_deg = 0.0;  ///< true, clockwise from north
};

class ImuScenario {
 public:
  ImuScenario(std::unique_ptr<Trajectory> trajectory, const Eigen::Vector3d& lever_arm_body_m,
              double rate_hz, double duration_s, double warmup_s, std::uint64_t seed,
              const ScenarioOptions& options, bool has_gnss = false);
  /// Produces the next sample and its truth; false once duration_s is reached (never if endless).
  bool next(ImuSample& imu, AttitudeTruth& truth);
  /// The GNSS fix that arrived with the last sample, if one did (only scenarios with a receiver).
  [[nodiscard]] const std::optional<GnssSpeedFix>& gnss_fix() const { return gnss_fix_; }
  [[nodiscard]] double rate_hz() const { return rate_hz_; }
  /// Start-up rest of the scenario: score accuracy after it (filters are initialising).
  [[nodiscard]] double warmup_s() const { return warmup_s_; }
  /// Where the sensor is from the trajectory's origin (m, body frame), the point whose velocity
  /// the GNSS fixes give: the installation's offset a boat node is configured with.
  [[nodiscard]] const Eigen::Vector3d& lever_arm() const { return lever_arm_; }
  [[nodiscard]] bool has_gnss() const { return has_gnss_; }

 private:
  std::unique_ptr<Trajectory> trajectory_;
  Eigen::Vector3d lever_arm_;
  double rate_hz_;
  double duration_s_;
  double warmup_s_;
  ScenarioOptions options_;
  ImuErrorModel errors_;
  std::mt19937_64 timing_rng_;
  std::uint64_t k_ = 0;
  double last_t_s_ = 0.0;
  Eigen::Quaterniond last_att_ = Eigen::Quaterniond::Identity();
  bool has_gnss_ = false;
  std::mt19937_64 gnss_rng_;  ///< its own: the IMU samples are the same with or without GNSS
  double next_gnss_epoch_s_ = 0.0;
  std::deque<GnssSpeedFix> gnss_pending_;  ///< epochs measured, not yet arrived (t_s = epoch)
  std::optional<GnssSpeedFix> gnss_fix_;
};

[[nodiscard]] const std::vector<std::string>& scenario_names();
/// Length of the scenario's scripted part (what tests and eval run), s.
[[nodiscard]] double scenario_default_duration_s(std::string_view name);
/// nullptr for an unknown name. duration_s <= 0: endless.
[[nodiscard]] std::unique_ptr<ImuScenario> make_scenario(std::string_view name, std::uint64_t seed,
                                                         double rate_hz, double duration_s,
                                                         const ScenarioOptions& options = {});

}  // namespace telltale::fusion::sim
