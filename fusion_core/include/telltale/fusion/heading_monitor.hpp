#pragma once
/// \file
/// "Should I fuse this heading reading?" — the fault monitor of the heading fusion (STYLE rule 6).
///
/// The algebra (heading_fusion.hpp) never decides which sensor is healthy: at every update it
/// asks HeadingSensorMonitor::assess() for the mapping matrices M_i of paper 002 (eq. 16, 20) as
/// a bit mask, and for a covariance inflation factor when the motion model itself is wrong.
///
/// What the monitor does (none of this is in the paper, which only defines M_i = I or 0):
/// - innovation of every reading against the global prediction, nu_i = wrap(y_i - psi^-);
/// - a robust reference: the median innovation of all sensors reading now, isolated ones
///   included (3 or more), else the innovation of the non-isolated sensor that agrees best with
///   the model (2), or the model itself (1);
/// - per reading, z_i = (nu_i - nu_ref)^2 / (r_i + r_ref): a chi-square(1) statistic of the
///   disagreement with the others. A reading with z_i > `sample_gate` is not fused (a spike);
/// - per sensor, the sum of the last `window` values of min(z_i, `stat_cap`): chi-square(window).
///   Above `exclude_threshold` the sensor is isolated (M_i = 0); it is re-admitted once the sum
///   has stayed below `readmit_threshold` for `readmit_hold_s` (hysteresis). Because a sensor
///   only comes back when it agrees with the fused heading, re-admission moves the output by no
///   more than its noise;
/// - a sensor whose value has not changed for `frozen_timeout_s` while the fused heading moved
///   `frozen_motion_deg` is frozen; one without a reading for `silent_timeout_s` is silent; both
///   come back through the same hysteresis;
/// - the model test: if the reference itself fails nu_ref^2 / (P_psi + r_ref) <= `model_gate`,
///   no sensor agrees with the motion model (a manoeuvre harder than Q allows, or a common-mode
///   fault). The monitor then follows the sensors' consensus and asks the algebra to inflate the
///   predicted covariance so that the consensus innovation becomes plausible (fading factor).
///
/// What it cannot do: with only two sensors left that drift apart slowly, nothing says which one
/// is right; the model breaks the tie (`sensors_disagree` is set so the node can alarm).

#include <array>
#include <cstdint>

namespace telltale::fusion {

/// Most heading sensors one fusion handles (fixed-capacity storage, no heap in update).
inline constexpr int kMaxHeadingSensors = 8;

/// Why a sensor is (not) in the fusion at the last update.
enum class HeadingSensorStatus : std::uint8_t {
  kNotConfigured = 0,  ///< index >= sensor_count
  kInUse,              ///< fused at this update (M_i = I)
  kNoReading,          ///< healthy, no reading at this update (lower rate than the caller)
  kSampleRejected,     ///< healthy sensor, this one reading failed the sample gate (a spike)
  kInconsistent,       ///< isolated: disagrees with the others (jump, bias step, drift)
  kFrozen,             ///< isolated: value stuck while the fused heading moved
  kSilent,             ///< isolated: no reading for silent_timeout_s
  kRecovering,         ///< consistent again, waiting readmit_hold_s before re-admission
  kNonFinite,          ///< the reading was +-Inf (counted, not fused); NaN means no reading
};

/// Short name for logs and CSV ("in_use", "inconsistent", ...).
[[nodiscard]] const char* heading_sensor_status_name(HeadingSensorStatus s);

/// Settings of HeadingSensorMonitor. Thresholds are chi-square quantiles; defaults in brackets.
struct HeadingMonitorParams {
  bool enabled = true;               ///< false: every finite reading is fused (no fault handling)
  double sample_gate = 15.14;        ///< per reading, chi2(1) 99.99 %
  int window = 10;                   ///< readings in the per-sensor window (1..32)
  double exclude_threshold = 29.59;  ///< window sum, chi2(10) 99.9 %
  double readmit_threshold = 23.21;  ///< window sum, chi2(10) 99 %: below it means consistent
  double readmit_hold_s = 2.0;       ///< consistent this long before re-admission, s
  double stat_cap = 100.0;           ///< one reading adds at most this to the window sum
  double model_gate = 15.14;         ///< reference vs motion model, chi2(1) 99.99 %
  double silent_timeout_s = 1.0;     ///< no reading this long -> kSilent, s
  double frozen_timeout_s = 2.0;     ///< identical readings this long ... , s
  double frozen_motion_deg = 2.0;    ///< ... while the fused heading moved this much -> kFrozen
  double max_rate_deg_s = 120.0;     ///< a lone sensor may not imply a faster turn than this
};

/// The monitor's answer for one update.
struct HeadingGateDecision {
  std::uint16_t use_mask = 0;       ///< bit i: fuse sensor i now (M_i = I)
  double covariance_inflation = 1;  ///< >= 1: multiply the predicted covariance by this
  bool model_mismatch = false;      ///< no sensor agrees with the motion model
  bool sensors_disagree = false;    ///< two candidates disagree; the model chose
  bool no_candidate = false;        ///< every present sensor was isolated; consensus of all used
};

class HeadingSensorMonitor {
 public:
  using Params = HeadingMonitorParams;
  struct SensorState {
    std::array<float, 32> window{};  ///< last `window` statistics (ring)
    int window_pos = 0;
    int window_fill = 0;
    double window_sum = 0.0;
    bool excluded = false;
    HeadingSensorStatus reason = HeadingSensorStatus::kNoReading;
    double consistent_since_s = 0.0;  ///< start of the current consistent stretch (if excluded)
    bool consistent = false;
    double last_reading_t_s = 0.0;
    bool ever_read = false;
    double last_value_deg = 0.0;  ///< last distinct value and when it changed
    double value_changed_t_s = 0.0;
    double fused_at_change_deg = 0.0;  ///< fused heading when the value last changed
    double last_stat = 0.0;            ///< z_i of the last reading
  };
  struct State {
    std::array<SensorState, kMaxHeadingSensors> sensors{};
    double last_fused_deg = 0.0;  ///< fused heading after the previous update
    double start_t_s = 0.0;       ///< time of the first assess()
    bool started = false;
  };

  explicit HeadingSensorMonitor(Params params = {}) : params_(params) {}

  /// Decides which readings to fuse at time t_s.
  /// - `reading_deg[i]`: latency-compensated heading of sensor i, NaN when it has no reading;
  /// - `r_deg2[i]`: its noise variance, deg^2, including the latency compensation's share;
  /// - `pred_heading_deg`, `pred_var_deg2`: the global prediction (psi^-, P^-_00) of this step;
  /// - `status` is filled for every i < n.
  /// Call once per update, before the measurement update; times must increase.
  HeadingGateDecision assess(double t_s, double dt_s, int n, const double* reading_deg,
                             const double* r_deg2, double pred_heading_deg, double pred_var_deg2,
                             HeadingSensorStatus* status);

  /// After the measurement update: the fused heading, for the frozen-sensor test.
  void note_fused(double fused_heading_deg) { state_.last_fused_deg = fused_heading_deg; }

  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Params& params() const { return params_; }

 private:
  void push_stat(SensorState& s, double stat) const;
  void exclude(SensorState& s, HeadingSensorStatus why) const;

  Params params_;
  State state_;
};

}  // namespace telltale::fusion
