#pragma once
/// \file
/// Telltale's production heel/pitch filter: the default of `fusion_cli attitude` and of the boat
/// node. It keeps the paper's idea (the accelerometer tells the vertical only where the motion is
/// inertial on average) and builds it from the physics, after Laidig & Seel's VQF (2023):
///   - strapdown: the gyro (minus the estimated bias) is integrated as a quaternion into an
///     almost-inertial frame I; each sample is the mean rate over the interval that ends at it
///     (a MEMS decimation filter), with the two-sample coning term; the accelerometer's sample
///     is rotated into I at the orientation of the instant it describes (mid-interval);
///   - the specific force is rotated into I and low-passed THERE by a 2nd-order Butterworth of
///     time constant tau_acc_s. In an earth-fixed frame the mean of the acceleration of any
///     bounded motion over T is dv / T -> 0, so waves, a pendulum's swing, a hand's shake and a
///     turntable's centripetal acceleration (which turns with the yaw) average out, while gravity
///     stays put. A steady turn is a rotation the gyro sees; it never looks like a tilt;
///   - the vertical is the direction of that low-passed vector (the inclination correction that
///     maps it to "up"), seen in the body through the gyro quaternion;
///   - the gyro bias is a Kalman state with its own 3x3 covariance: learnt at rest (rest = the
///     gyro AND the accelerometer steady about their own 0.5 s means, AND the gyro reading what
///     the bias can be: a constant rotation is not rest, nor a boat the GNSS sees making way),
///     in motion from how fast the low-passed vertical drifts in I (horizontal components only:
///     the bias about the vertical does not move the vertical), and about the vertical from the
///     GNSS course when it is given (the gyro's turn against the course's over tau_acc_s);
///   - the gyro's common scale error is a fourth state of that filter, learnt in motion from the
///     same drift: a gyro reading (1 - k) of the rate turns frame I at k times the rate in I,
///     so the drift is the bias error through LP(R) plus the scale error through LP(R omega).
///     It matters where the rotation is fast and one-way (a hand tumbling the sensor at
///     400 deg/s: 0.5 % of it is 2 deg/s of drift); a boat's rolling back and forth cancels it;
///   - the skew between the accelerometer's and the gyro's signal chains (their digital filters
///     delay them differently, a few ms on MEMS parts) is a fifth state of that filter: a force
///     seen s late is seen from an attitude turned by omega s, so the low-passed force in I
///     carries s LP(R (f x omega)), a tilt while a rotation lasts; its onset and end move the
///     vertical, and that drift measures s;
///   - start: the low-pass starts as the mean of everything seen since (the best estimate of a
///     constant from a growing window) for tau_acc_s, as it does after a gap too long to
///     integrate. If within the first start_fit_s (and before any rest or gap) the GNSS speed
///     shows the sensor under way, the start is a hull's in a seaway: from then on, for
///     start_fit_s, the vertical and the bias are one Kalman filter on 5 states, the
///     least-squares line through the specific force in I (intercept: the tilt, slope: the
///     bias), its acceleration noise measured as it goes; the low-pass then takes over in its
///     steady state with that bias and covariance. Without GNSS (a phone, a bench) the line
///     fit never runs. Nothing is learnt from the drift until the growing mean has become the
///     Butterworth (its drift is not the model's). A restart may begin from the calibration the
///     filter had learnt (warm_start) instead of the datasheet's spread;
///   - the boat's own acceleration, when its speed is known (set_speed, from GNSS): a boat
///     turning at w about the vertical at speed v accelerates at w v toward the inside of the
///     turn, and speeding up at dv/dt along its heading. A tack's few seconds of that are one
///     direction in I for longer than the low-pass can average out (it would read as heel);
///     known, it is taken off the specific force before the low-pass; and a sensor away from the
///     boat's centre (Params::lever_arm_m, the installation's offset) swings about it at
///     omega x r, which is taken off too (d(omega)/dt x r + omega x (omega x r));
///   - non-uniform time steps, dropped samples, saturated samples, NaN/Inf.
///
/// Call order: update() once per sample, time strictly increasing; read output() afterwards.
/// Cannot observe: the gyro bias about the vertical without GNSS course (heading drift;
/// irrelevant to heel/pitch until the boat heels the other way or turns), the gyro's scale
/// without rotation across the vertical (nor does it matter then), its axes' own scales and
/// cross-axis errors apart from their common part,
/// an accelerometer offset (it becomes a tilt error of offset/g rad), a linear acceleration that
/// is sustained in one earth direction for longer than ~tau_acc_s (its mean is a tilt) unless it
/// is the turn and speed change of a boat whose speed is given.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

/// Settings of TelltaleAttitudeFilter.
struct TelltaleAttitudeParams {
  double g_m_s2 = kStandardGravity_m_s2;
  /// Time constant of the 2nd-order Butterworth low-pass on the specific force in frame I
  /// (cut-off sqrt(2) / (2 pi tau)). 3 s: longer than a wave, a pendulum's 2 s period and a
  /// hand's shake (they average out), short against the drift a residual bias of 0.1 deg/s makes.
  double tau_acc_s = 3.0;
  /// The same while at rest (the specific force is gravity: nothing to average out).
  double tau_acc_rest_s = 0.5;
  /// Rest detection: deviations of the gyro / accelerometer from their own rest_lp_tau_s
  /// low-pass below these for rest_min_s.
  double rest_gyro_rad_s = 2.0 * M_PI / 180.0;
  double rest_acc_m_s2 = 0.5;
  double rest_min_s = 1.5;
  double rest_lp_tau_s = 0.5;
  /// Rest also needs the gyro's mean to be a possible bias: within 3 sigma of the bias estimate
  /// on each axis, and never further than this floor below it (a steady turn of more than
  /// 0.5 deg/s is a turn, not a rest).
  double rest_bias_gate_rad_s = 0.5 * M_PI / 180.0;
  /// Never at rest while the GNSS speed (set_speed) is above this: ten times a receiver's
  /// velocity noise (0.05 m/s), the boat is moving and rocks with the water.
  double rest_max_speed_m_s = 0.5;
  /// Bias Kalman filter (units rad/s). Initial sigma: the zero-rate spread of an uncalibrated
  /// MEMS gyro (L3G4200D +-10 deg/s uniform -> 5.8 deg/s); at rest the gyro mean is a
  /// measurement of 0.03 deg/s; in motion the steady-state sigma is 0.1 deg/s; the bias is
  /// forgotten at (0.1 deg/s)^2 per bias_forgetting_s (temperature drift).
  double bias_sigma_init_rad_s = 5.8 * M_PI / 180.0;
  double bias_sigma_rest_rad_s = 0.03 * M_PI / 180.0;
  double bias_sigma_motion_rad_s = 0.1 * M_PI / 180.0;
  double bias_forgetting_s = 100.0;
  double max_bias_rad_s = 20.0 * M_PI / 180.0;     ///< |bias| clamp (twice the L3G4200D spread)
  /// The gyro's common scale error k (rate = (1 + k)(gyro - bias)), a Kalman state beside the
  /// bias, learnt in motion only (update says how). Prior sigma: what a calibration leaves of a
  /// MEMS gyro's sensitivity error common to its axes, and a sample clock's error (every rate is
  /// integrated over the stamped interval): 0.5 %. Forgotten back to it over
  /// gyro_scale_forgetting_s (the sensitivity moves with temperature: +-2 % over -40..85 degC,
  /// L3G4200D, some 0.02 %/degC).
  double gyro_scale_sigma_init = 0.005;
  double gyro_scale_forgetting_s = 3600.0;
  double max_gyro_scale = 0.05;  ///< |k| clamp: beyond any MEMS sensitivity tolerance
  /// The accelerometer's delay against the gyro's (s > 0: its sample describes an instant s
  /// earlier than the gyro's mid-interval), a Kalman state beside the bias and the scale, learnt
  /// in motion only (update says how). Prior sigma: the spread of the difference between a MEMS
  /// part's two filter delays (1-4 ms on common parts, more at low output rates): 5 ms. Forgotten
  /// back to it over acc_skew_forgetting_s (a configuration's figure: it changes only when the
  /// sensor is set up again; the forgetting lets a wrong start be unlearnt). 0: not a state.
  double acc_skew_sigma_init_s = 5e-3;
  double acc_skew_forgetting_s = 3600.0;
  double max_acc_skew_s = 0.02;                    ///< |s| clamp
  double gyro_range_rad_s = 250.0 * M_PI / 180.0;  ///< full scale (L3G4200D default 250 dps)
  double acc_range_m_s2 = 2.0 * kStandardGravity_m_s2;  ///< full scale (LSM303DLH default 2 g)
  double saturation_fraction = 0.98;                    ///< |reading| >= this * range -> saturated
  double max_gap_s = 1.0;  ///< longer gaps are not integrated (the low-pass restarts)
  /// Group delay of the IMU: its samples describe the motion this long before their time stamp
  /// (a MEMS sensor's digital low-pass and its transfer take a few ms). The output is carried
  /// forward over it with the gyro (output() only). 2.5 ms: the lag of BROAD's IMU behind its
  /// optical reference, the same on all eight shared trials (1.75..3.5 ms all within 0.01 deg of
  /// the best mean); a rotation at w rad/s moves the vertical by w * delay, so a wrong delay
  /// costs at most 0.25 deg at 100 deg/s. Set it to the boat's sensor's figure when known.
  double sensor_delay_s = 2.5e-3;
  /// The error of a GNSS course rate (set_speed) as the low-pass sees it, against which the
  /// gyro's rate about the vertical is weighed when its bias there is not known: 0.05 m/s of
  /// velocity noise is 1.1 deg of course at 2.5 m/s, sqrt(2) * 1.1 / tau_acc_s = 0.5 deg/s over
  /// the low-pass's window, and the bow and the track part by a few degrees of leeway that
  /// changes over a tack: 1 deg/s.
  double cog_rate_sigma_rad_s = 1.0 * M_PI / 180.0;
  /// Start (see update): when the GNSS speed shows the sensor under way (above
  /// rest_max_speed_m_s) within start_fit_s of the first sample, before any rest or gap, the
  /// vertical and the gyro bias are one Kalman filter (the least-squares line through the
  /// specific force in I) instead of the low-pass and its drift, for start_fit_s from then.
  /// 5 s: two periods of the slowest sea the low-pass is built for (0.3-0.5 Hz), so that the
  /// line's slope is not one wave's half swing. 0: never.
  double start_fit_s = 5.0;
  /// The horizontal acceleration of the sensor before any sample has been seen, one axis: a
  /// boat's in a seaway (waves' heave, surge and sway ~1.5 m/s^2 at the bow). The first sample's
  /// tilt is known to this / g, and it is the prior of the acceleration's variance.
  double start_acc_sigma_m_s2 = 2.0;
  /// How long a seaway's acceleration keeps its direction (its correlation time): 1 / omega of a
  /// 0.5 Hz wave, the quickest the low-pass is built for. The start's filter counts the samples
  /// within it as one measurement (their variance times this over dt), so that 100 Hz is not
  /// believed four times better than 25 Hz.
  double wave_corr_s = 0.3;
  /// Where the sensor is mounted (m, body frame: x forward, y to port, z up) from the point the
  /// hull turns about and whose velocity set_speed gives (the boat's centre; its GNSS antenna
  /// when that is there). An installation figure, like sensor_delay_s: measured on the boat, not
  /// tuned; zero (the default) leaves the filter exactly as without it. A sensor off the centre
  /// moves relative to it at omega x r: the bow of a dinghy (1.5 m ahead) swings sideways at
  /// 1.2 m/s through a tack's 0.8 rad/s turn, and pitches and yaws with every wave. That motion
  /// is bounded, but over a tack it is one direction in I for the seconds the low-pass averages
  /// (update), and what is left is heel. Used with the speed (set_speed) only: it makes the
  /// sensor's specific force the centre's, which the speed's model describes; with the speed
  /// unknown the filter is exactly as without it.
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
};

/// `p` for a sensor of these full scales (a scale not known keeps p's).
[[nodiscard]] TelltaleAttitudeParams with_ranges(TelltaleAttitudeParams p,
                                                 const SensorRanges& ranges);
/// `p` for a sensor whose full scales its user is not told (a wearable's part is its maker's):
/// nothing is taken for clipped.
[[nodiscard]] TelltaleAttitudeParams without_ranges(TelltaleAttitudeParams p);

/// What TelltaleAttitudeFilter has learnt of its sensor (the gyro's bias, its common scale
/// error, the accelerometer's skew) with their covariance, in the filter's units: kept across a
/// restart, so that a node started again on the water does not begin from the datasheet's
/// spread (TelltaleAttitudeFilter::calibration, warm_start).
struct TelltaleCalibration {
  Eigen::Vector3d bias_rad_s = Eigen::Vector3d::Zero();
  double gyro_scale = 0.0;
  double acc_skew_s = 0.0;
  /// (bias x, y, z, scale, skew): the filter's State::cov.
  Eigen::Matrix<double, 5, 5> cov = Eigen::Matrix<double, 5, 5>::Zero();
};

class TelltaleAttitudeFilter final : public AttitudeFilter {
 public:
  using Params = TelltaleAttitudeParams;
  /// Everything the update carries from one sample to the next (copyable, fixed size).
  struct State {
    Eigen::Quaterniond q_gyro = Eigen::Quaterniond::Identity();  ///< body -> inertial frame I
    Eigen::Vector3d bias_rad_s = Eigen::Vector3d::Zero();        ///< gyro bias, body
    /// The rotation increment of the last update (rad, body; 0 after a gap): the coning term's
    /// other half (update).
    Eigen::Vector3d dtheta_prev_rad = Eigen::Vector3d::Zero();
    /// The gyro's common scale error (Params::gyro_scale_sigma_init): rate = (1 + k)(gyro - bias).
    double gyro_scale = 0.0;
    /// The accelerometer's skew against the gyro (s; Params::acc_skew_sigma_init_s).
    double acc_skew_s = 0.0;
    /// The covariance of (bias, scale, skew), one Kalman filter on 5 states: the bias's 3x3
    /// block in (rad/s)^2 top left, the scale's variance at (3, 3), the skew's (s^2) at (4, 4),
    /// their covariances between.
    Eigen::Matrix<double, 5, 5> cov = Eigen::Matrix<double, 5, 5>::Zero();
    /// Low-passed in frame I, as one block: column 0 the specific force (m/s^2), 1..3 the
    /// rotation matrix body -> I, 4 R * bias (the motion-bias model), 5 R * (gyro - bias) (the
    /// scale's: the rate in I), 6 R * (f x omega) (the skew's: how a late force tilts). Output
    /// and two Butterworth (transposed direct form II) states.
    Eigen::Matrix<double, 3, 7> lp = Eigen::Matrix<double, 3, 7>::Zero();
    Eigen::Matrix<double, 3, 7> lp_s0 = Eigen::Matrix<double, 3, 7>::Zero();
    Eigen::Matrix<double, 3, 7> lp_s1 = Eigen::Matrix<double, 3, 7>::Zero();
    double tau_scale = 1.0;     ///< tau_acc_s / the time constant in use (>= 1, see update)
    double lp_elapsed_s = 0.0;  ///< time since the low-pass (re)started
    bool lp_running = false;    ///< false: still the growing mean of the fast start
    Eigen::Vector3d up_i = Eigen::Vector3d::UnitZ();       ///< the vertical in I (unit)
    Eigen::Vector3d bias_up_i = Eigen::Vector3d::UnitZ();  ///< up_i at the last motion update
    Eigen::Vector3d bias_skew_lp = Eigen::Vector3d::Zero();  ///< lp column 6 then
    double bias_elapsed_s = 0.0;                           ///< time since then
    Eigen::Vector3d gyro_rest_lp_rad_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d acc_rest_lp_m_s2 = Eigen::Vector3d::Zero();
    double rest_time_s = 0.0;
    /// The accelerometer's squared deviation from its rest low-pass in the last update
    /// ((m/s^2)^2; +Inf when saturated): output() makes it the reported weight.
    double acc_dev2 = std::numeric_limits<double>::infinity();
    double last_t_s = 0.0;
    /// The output's inputs (output() is computed from them on demand): the vertical seen in the
    /// body (unit) and the bias-corrected body rate of the last update.
    Eigen::Vector3d up_body = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Zero();
    bool initialised = false;
    bool updated = false;  ///< an update followed the first sample
    /// The boat's speed as last given by set_speed (NaN: unknown) and its rate of change.
    double speed_m_s = std::numeric_limits<double>::quiet_NaN();
    double speed_rate_m_s2 = 0.0;
    double yaw_rate_cog_rad_s = std::numeric_limits<double>::quiet_NaN();  ///< - cog rate
    /// The start's Kalman filter (update): still possible (no GNSS speed under way yet, no rest,
    /// no gap, start_elapsed_s the time since the first sample), running, its covariance (the
    /// tilt of up_i about two horizontal axes, rad, then the bias, rad/s), its age and the
    /// variance of the horizontal specific force it measures (one axis, in units of g^2).
    bool start_pending = false;
    bool start_fit = false;
    Eigen::Matrix<double, 5, 5> start_cov = Eigen::Matrix<double, 5, 5>::Zero();
    double start_elapsed_s = 0.0;
    double start_acc_var = 0.0;
    /// The bias about the vertical against the GNSS course: over the current window, its length,
    /// the raw gyro integrated about the vertical, the course's turn (-cog) and the vertical in
    /// the body integrated (rad, rad, s).
    double course_window_s = 0.0;
    double course_gyro_rad = 0.0;
    double course_turn_rad = 0.0;
    Eigen::Vector3d course_up_s = Eigen::Vector3d::Zero();
    /// The raw gyro of the last update, for the lever arm's angular acceleration (update); kept
    /// only when Params::lever_arm_m is not zero.
    Eigen::Vector3d lever_gyro_prev_rad_s = Eigen::Vector3d::Zero();
  };
  /// The gate's counts (gaps: not integrated, the low-pass restarted; accelerometer saturated:
  /// not used for the bias or rest) and the samples spent learning the bias at rest.
  struct Diagnostics : ImuGateCounts {
    unsigned rest_samples = 0;
  };

  explicit TelltaleAttitudeFilter(Params params = {});
  void update(const ImuSample& sample) override;
  /// The boat's speed over ground (m/s; through the water is better when known, see below), its
  /// rate of change (m/s^2) and the rate of the course over ground (rad/s, clockwise +), used by
  /// every update until the next call. NaN speed = unknown: the filter then behaves exactly as
  /// without it; NaN speed rate = 0; NaN course rate = unknown (the gyro's rate is used). The
  /// model: the velocity is horizontal, along the bow's horizontal direction (no leeway), so the
  /// boat's acceleration is dv/dt along the bow plus (turn rate about the vertical) x v. The
  /// turn rate is the gyro's about the vertical, weighed against the course rate by their
  /// variances: the gyro's bias about the vertical cannot be learnt in motion, so a node started
  /// under way knows it only to bias_sigma_init (5.8 deg/s: 0.25 m/s^2 of false turn at
  /// 2.5 m/s), and there the course rate is better; once a rest has measured the bias, the gyro
  /// (no latency, no noise) is. In a current c the turn term of a speed over ground is off by
  /// w x c (0.5 m/s of current against 2.5 m/s of boat speed: a fifth). The model is the
  /// centre's: a sensor away from it (on the bow) swings about it, which Params::lever_arm_m
  /// takes off when the installation gives it (the tangential part of a tack's turn does not
  /// cancel within the low-pass: 1.2 m/s of sideways swing on a dinghy's bow, 1.3-1.6 deg of
  /// heel, docs/attitude.md).
  void set_speed(double speed_m_s, double speed_rate_m_s2, double cog_rate_rad_s) override;
  /// Computed on demand from the state (update() does not pay for the two atan2).
  [[nodiscard]] AttitudeOutput output() const override;
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  /// The bias, scale and skew as learnt so far, and their covariance.
  [[nodiscard]] TelltaleCalibration calibration() const;
  /// Begin (at the next first sample: call it before the first update, or the filter takes it
  /// at its next start) from a calibration saved age_s ago instead of the priors. The sensor has
  /// drifted since by the filter's own random walks (the bias at (bias_sigma_motion)^2 per
  /// bias_forgetting_s, the scale and the skew likewise), so each variance grows by that over
  /// age_s; one that reaches its prior is the prior again (uncorrelated: nothing is left of
  /// what was learnt). Refused (false; the priors stay) when the calibration is not one this
  /// filter could have learnt: a value not finite or beyond its clamp, a covariance not
  /// symmetric or with a negative variance in any combination of the states, or age_s negative
  /// or not finite.
  bool warm_start(const TelltaleCalibration& c, double age_s);
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const Params& params() const { return params_; }

 private:
  void initialise(const ImuSample& s);
  /// The start's wait for a GNSS speed under way (update): ends it at a rest or after
  /// start_fit_s, begins the line fit when the speed comes. Runs for the first seconds only; not
  /// inlined (inlined into update() it changes the inlining of the steady path's products:
  /// callgrind +35 instructions per update).
  [[gnu::noinline]] void start_wait(bool at_rest, bool gap, double dt);
  /// One sample of the start's Kalman filter (tilt of up_i and bias); r: body -> I, f: the
  /// specific force without the boat's own acceleration. Not inlined: it runs for the first
  /// seconds only, and inlined into update() it crowds out the inlining of the steady path's
  /// small products (callgrind: +90 instructions per update).
  [[gnu::noinline]] void start_fit_update(const Eigen::Matrix3d& r, const Eigen::Vector3d& f,
                                          double dt);
  /// The bias about the vertical from the GNSS course (every tau_acc_s while the course is
  /// known). Called only while the course is known or a window is open; not inlined (the same).
  [[gnu::noinline]] void course_update(const Eigen::Vector3d& gyro_raw, bool usable, double dt);
  /// The specific force of the sensor's motion about the centre (Params::lever_arm_m), from the
  /// raw gyro (its change since the last update) and the bias-corrected one. Only with an offset
  /// configured; not inlined (inlined, the untaken branch alone cost +48 instructions per update
  /// through the compiler's inlining of the steady path, callgrind).
  [[gnu::noinline]] Eigen::Vector3d lever_arm_force(const Eigen::Vector3d& gyro_raw,
                                                    const Eigen::Vector3d& gyro, double dt) const;
  Params params_;
  ImuGateParams gate_;  ///< the sensor's ranges and the longest gap, from params_
  bool lever_ = false;  ///< params_.lever_arm_m is not zero
  /// M_SQRT1_2 / tau of the usual step (tau_scale 1, see update): in motion and at rest.
  double inv_sqrt2_tau_motion_ = 0.0;
  double inv_sqrt2_tau_rest_ = 0.0;
  State state_;
  Diagnostics diag_;
  /// warm_start's calibration, its covariance already grown by its age: what initialise()
  /// starts from when have_warm_.
  TelltaleCalibration warm_;
  bool have_warm_ = false;
};

}  // namespace telltale::fusion
