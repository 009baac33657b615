#pragma once
/// \file
/// Hand-held phone PDR stage (HandheldPdr, handheld_pdr.hpp): the gyro bias from the walker
/// standing still (a hand, not a table), its component about the vertical from the magnetometer
/// during stands. Owns its window and stand sums and the estimate. Also the magnetic heading of
/// a phone axis, which this stage's magnetic yaw and HandheldPdr's track orientation share.
///
/// Memory: fixed-size Eigen types, no heap.

#include <Eigen/Core>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// Heading (clockwise from magnetic north) of the horizontal part of `axis`, from the field and
/// the up direction (same frame); NaN when degenerate.
[[nodiscard]] double handheld_magnetic_heading(const Eigen::Vector3d& mag,
                                               const Eigen::Vector3d& up,
                                               const Eigen::Vector3d& axis);
/// The phone's forward axis: the horizontal part of y - z is the top of the screen for a phone
/// held flat or tilted toward the face, and stays horizontal-capable for a phone held upright.
inline const Eigen::Vector3d kHandheldForward(0.0, 1.0, -1.0);

/// Gyro bias from standing. A hand holding a phone is never still (tremor: 0.05-0.25 rad/s rms,
/// acceleration 0.05-0.4 m/s^2 rms), so no single second gives the bias; but the phone's
/// orientation stays put while the walker stands, so over a stand of T seconds the mean rate is
/// the bias plus (net rotation) / T: a few degrees over a 20 s stand, under 0.005 rad/s. Each
/// stand is weighted by T^2 (its error goes as 1/T) and the current stand counts as it grows.
struct StandBiasParams {
  double window_s = 1.0;  ///< quiet test window
  /// Quiet: |f| rms about its mean and the rate rms below these over the window. A walking step
  /// moves |f| by 1-3 m/s^2 (heel strike), handling turns the phone at 2-7 rad/s; a hand
  /// holding it stays below both.
  double max_acc_sd_m_s2 = 0.4;
  double max_gyro_rms_rad_s = 0.4;
  double min_stand_s = 3.0;  ///< shorter quiet stretches are pauses of a moving hand
  /// A stand's mean rate above this is a slow turn on the spot, not a bias (phone gyros are
  /// factory- and OS-calibrated to well under 1 deg/s).
  double max_bias_rad_s = 0.03;
  /// The bias about the vertical from the magnetometer during stands. A standing walker stays
  /// on one spot, so the field there is one fixed vector even when indoor iron bends it; the
  /// phone's yaw change over the stand is then the change of the field's horizontal direction
  /// seen from the phone (tilt-compensated), and d = (gyro yaw) - (magnetic yaw) grows as
  /// bias * t whatever the hand's yaw wander does (the wander is in both and cancels). Its slope
  /// (least squares over the stand's samples) is the bias about the stand's vertical; the other
  /// two components stay the gyro learner's. Never used while walking: the walker then moves
  /// through the field's disturbances, and a direction change of the field is not a turn.
  /// Stands are combined by the inverse variance of their slopes (see StandBiasLearner::State).
  bool mag_yaw_bias = true;
  /// The magnetic yaw's noise goes as 1/|B horizontal|: below this (a field nearly along the
  /// vertical, or a dead sensor) a stand says nothing. Earth's horizontal field is 10-40 uT.
  double min_mag_horizontal_uT = 5.0;
  /// |B| is the same at one spot whatever the phone's orientation; a stand whose |B| varies by
  /// more than this (rms) had the phone moved past a magnetic source (or the walker stepped),
  /// so its field was not one fixed vector: no estimate from it.
  double max_mag_norm_sd_uT = 2.0;
};
class StandBiasLearner {
 public:
  using Params = StandBiasParams;
  struct State {
    // Window sums.
    double win_t0_s = 0.0;
    int win_n = 0;
    double win_a = 0.0, win_a2 = 0.0, win_w2 = 0.0;
    Eigen::Vector3d win_w = Eigen::Vector3d::Zero();
    // The stand in progress (consecutive quiet windows) and the stands before it.
    double stand_s = 0.0;
    Eigen::Vector3d stand_w_dt = Eigen::Vector3d::Zero();  ///< integral of the rate
    double done_weight = 0.0;                              ///< sum of T^2
    Eigen::Vector3d done_sum = Eigen::Vector3d::Zero();    ///< sum of T^2 * mean
    Eigen::Vector3d bias = Eigen::Vector3d::Zero();
    // Magnetic yaw: psi_g = integral of w . up (raw gyro), psi_m = the phone's yaw from the
    // field (unwrapped, counter-clockwise), d = psi_g - psi_m. Least-squares sums of d against t
    // (t from the first sample) over the window and over the stand, d^2 for the residual about
    // the fitted line (the slope's variance); |B| sums for its rms.
    struct YawSums {
      double n = 0.0, t = 0.0, d = 0.0, tt = 0.0, td = 0.0, dd = 0.0, b = 0.0, bb = 0.0, bh = 0.0;
      Eigen::Vector3d up = Eigen::Vector3d::Zero();
      void add(const YawSums& o) {
        n += o.n;
        t += o.t;
        d += o.d;
        tt += o.tt;
        td += o.td;
        dd += o.dd;
        b += o.b;
        bb += o.bb;
        bh += o.bh;
        up += o.up;
      }
    };
    double psi_g = 0.0, psi_m = 0.0, psi_m_raw = 0.0;
    bool have_psi_m = false;
    double t_origin_s = 0.0;  ///< t origin of the sums (the first sample)
    YawSums win_yaw, stand_yaw;
    bool win_yaw_ok = true;    ///< every sample of the window had a usable field
    bool stand_yaw_ok = true;  ///< and every window of the stand
    /// The stands with a magnetic slope, each weighted by the inverse variance of its slope,
    /// T^3 / (rms residual of d about its line)^2 (mag_slope_weight in the source).
    double mag_weight = 0.0;  ///< sum of the weights
    double mag_sum = 0.0;     ///< sum of weight * slope (rad/s about that stand's up)
    Eigen::Vector3d mag_up = Eigen::Vector3d::Zero();  ///< sum of weight * the stand's mean up
    double vertical_bias = 0.0;  ///< the magnetic estimate about mag_up (valid if mag_weight > 0)
    bool quiet = false;          ///< the last full window was quiet
    bool have_bias = false;
    double last_t_s = 0.0;
    bool started = false;
  };
  explicit StandBiasLearner(Params p = {}) : params_(p) {}
  /// One sample with the up direction (unit, phone frame) and the field (NaN: none).
  void update(const ImuSample& s, const Eigen::Vector3d& up, const Eigen::Vector3d& mag_uT);
  /// The bias: the gyro learner's, its component along the stands' vertical replaced by the
  /// magnetic estimate once a stand gave one.
  [[nodiscard]] const Eigen::Vector3d& bias_rad_s() const { return state_.bias; }
  /// The magnetic estimate of the bias about the vertical (rad/s) and whether there is one.
  [[nodiscard]] bool has_mag_vertical_bias() const { return state_.mag_weight > 0.0; }
  [[nodiscard]] double mag_vertical_bias_rad_s() const { return state_.vertical_bias; }
  [[nodiscard]] bool quiet() const { return state_.quiet; }
  [[nodiscard]] const State& state() const { return state_; }

 private:
  void close_stand();
  void clear_window();
  void update_estimate();
  /// The stand's magnetic slope into the sums (if it qualifies).
  void close_mag_stand();
  Params params_;
  State state_;
};

}  // namespace telltale::fusion
