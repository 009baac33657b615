#pragma once
/// \file
/// The gait-phase step detector: every step of a real walk that starts and stops, on a foot or on
/// the trunk (the input contract and the registry are in steps.hpp).

#include <array>
#include <cstddef>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {

/// Gait phases, for real walks that start and stop. The adaptive and peak-valley
/// detectors need a few steps of history before their thresholds describe the walk, so on real
/// recordings (stand, walk 10 m, turn, walk back, stop) they lost the first steps after standing
/// and the last before stopping, 2-4 a walk. This detector needs no history: every rule is a
/// property of one step, fixed by the physics of gait.
///
/// Foot (`StepMount::kFoot`, counts that foot's steps): a step is one swing of the foot between
/// two stances. In stance the foot is flat on the ground and barely turns (|w| a few 0.01 rad/s
/// standing, below ~0.25 x the swing's peak rate in a brisk walk, whose stance still rolls
/// heel-to-toe); in swing it turns about the medio-lateral axis by 30-100 deg (toe-off, swing,
/// heel strike) and its specific force leaves 1 g (push-off, swing, impact). So: a swing starts
/// when the smoothed |w| exceeds `swing_enter_rad_s` and ends when the foot is still again: the
/// rate below the stance level (`stance_abs_rad_s`, or `stance_fraction` x this swing's peak)
/// and |f| within `stance_acc_m_s2` of the accelerometer's own g (|f| averaged over `g_tau_s` of
/// stance: the IPOL left feet read 10.0-10.5 m/s^2 standing) for `stance_hold_s`. A foot that
/// has stopped turning in the air still decelerates at several g, one pivoting on its ball in a
/// turn before it swings is loaded and moving; a foot flat on the ground reads gravity alone
/// once the impact has rung out. A swing is a step when it turned through `min_swing_deg`,
/// peaked at `min_peak_rad_s` and |f| left g by `min_acc_m_s2` -- small enough for the short
/// first step from standing and the closing step, well above a weight
/// shift while standing (< 0.3 rad/s, < 0.5 m/s^2 on the IPOL recordings). The event time is the
/// heel strike: the swing turns the foot about its medio-lateral axis (toes up through the swing,
/// the largest rotation of the cycle); at the end of the swing the rate about that axis reverses
/// as the heel is lowered, and the heel meets the ground within a few hundredths of a second:
/// the step is reported at the largest |f| (the impact) within `impact_window_s` after the
/// reversal (the axis: the principal direction of the swings' rates, learnt over the steps;
/// the run: of the toes-up sense, that of the swings' largest runs, so that a pivot on the ball
/// of the foot before a swing, which turns it the other way, is not taken for the swing).
/// A swing whose rate never reverses is reported at its landing (the last moment the rate was
/// above half the swing's peak, 0.1-0.2 s after the heel strike).
/// A foot cannot step less than `min_step_interval_s` after its last step's time (the other
/// foot swings in between: 2.5 cycles/s is beyond a sprint), nor sooner than
/// `interval_fraction` of its recent cycle: that merges a landing that settles in two motions.
/// The force excursion counts only while the foot turns (a heel rising over the toes turns at
/// |f| = g).
///
/// Body (`StepMount::kBody`, every step): the trunk rises and falls once per step (the centre of
/// mass vaults over the stance leg, then is caught by the next heel strike), so its vertical
/// acceleration oscillates at the step frequency, 1-3 m/s^2 in a walk. Vertical = along the
/// slowly low-passed specific force (gravity in the sensor frame, any mounting). Each rise of
/// `hysteresis_abs_m_s2` (or `hysteresis_fraction` x the recent peak-to-valley) after a valley,
/// followed by a fall of as much, is one step (the loading after the heel strike), reported at
/// its peak's time less the low-pass's delay at the walk's step frequency: the heel strike's
/// time. The first step after standing has no history to compare with, so only the physical
/// floor applies (standing sway: < 0.1 m/s^2); but a walk that starts from standing begins with
/// the push of its first toe-off, which lifts the trunk too, by a fraction of a step's loading.
/// So a walk's first step is held until the next `first_step_followers` (or the walk's end) and
/// counts only if its peak reaches `first_step_fraction` of theirs (their median). A walk from
/// standing can begin with two such rises, the weight shifted onto the stance leg and then the
/// push, 0.3-0.6 s apart (IPOL 2-1, 2-4, 4-1: the first 0.23-0.29 of the walk's peaks, the
/// second 0.12, 0.35 and 0.65): when the first is dropped, the next is judged the same way, up to
/// `first_steps_judged`.
/// The closing step of a walk, the heel strike that brings the trunk to rest, is no such rise
/// and fall: its loading lifts the vertical from the last fall (the trunk vaulting over the
/// stance leg) and the trunk then stands, with no fall after it for the rule above, and often
/// less than its floor (IPOL lower back: 0.12-1.2 m/s^2, missed in 14 of 22 files). So a rise
/// of `closing_rise_m_s2` since the lowest point after the walk's last step, steep as a heel
/// strike's loading is (`closing_rise_m_s2` within `closing_rise_s`: the weight accepted in
/// ~0.1 s; the gravity estimate settling after a walk drifts at under 1 m/s^3), after which the
/// vertical stays within `rest_band_m_s2` (a standing trunk's sway) for `rest_s`, is the
/// closing step: one per walk, within `pause_s` of its last step and, by its steepest rise, at
/// least `min_body_interval_s` after it (the trunk settling after a closing step the rise-and-fall
/// rule counted, 0.11-0.18 s after that step's peak, is no second one). It is reported at the
/// rise's lowest point (the heel strike ended the fall), less the low-pass's delay.
///
/// Both hold from 50 to 200 Hz: every filter and duration is in seconds, none in samples.
struct GaitPhaseStepParams {
  StepMount mount = StepMount::kFoot;
  // Foot.
  double rate_cutoff_hz = 5.0;       ///< low-pass on |w| (a swing lasts 0.3-0.5 s), Hz
  double swing_enter_rad_s = 1.0;    ///< smoothed |w| that starts a swing, rad/s
  double stance_abs_rad_s = 0.5;     ///< smoothed |w| below this is stance, rad/s
  double stance_fraction = 0.25;     ///< ...or below this x the swing's peak |w|
  double stance_acc_m_s2 = 2.0;      ///< ...and ||f| - own g| below this, m/s^2
  double stance_hold_s = 0.04;       ///< ...for this long, s
  double g_tau_s = 2.0;              ///< |f| averaged over stances: the accelerometer's own g, s
  double min_swing_deg = 11.5;       ///< smallest rotation of a step's swing, deg
  double min_peak_rad_s = 1.0;       ///< smallest peak smoothed |w| of a swing, rad/s
  double min_acc_m_s2 = 2.0;         ///< smallest ||f| - g| during a swing, m/s^2
  double landing_fraction = 0.5;     ///< landing = last time |w| was above this x peak
  bool report_heel_strike = true;    ///< report the heel strike (false: the landing)
  double impact_window_s = 0.05;     ///< the impact is sought this long after the reversal, s
  double axis_keep = 0.9;            ///< memory of the medio-lateral axis, per step
  /// The toes-up sense is used once the swings' largest runs add up to this along the axis (each
  /// counts 1, forgotten by axis_keep a step: two or three swings that agree).
  double toes_up_sure = 2.0;
  double min_step_interval_s = 0.4;  ///< same foot, between step events, s
  double interval_fraction = 0.6;    ///< ...and at least this x the recent gait cycle
  // Body.
  double gravity_tau_s = 1.0;         ///< time constant of the gravity direction, s
  double vertical_cutoff_hz = 3.0;    ///< low-pass on the vertical acceleration, Hz
  double hysteresis_abs_m_s2 = 0.4;   ///< smallest rise/fall that is a step, m/s^2
  double hysteresis_fraction = 0.2;   ///< ...or this x the recent peak-to-valley
  double min_body_interval_s = 0.25;  ///< between steps (4 steps/s), s
  double pause_s = 2.0;  ///< longer without a step: amplitude and cycle memories are reset
  /// Body: a walk's first step counts only if its peak reaches this fraction of the peaks of the
  /// steps after it (their median over at most first_step_followers). The trunk's rise at the
  /// first toe-off of a walk from standing is the swing leg's push: 0.07-0.39 of the walk's
  /// loading peaks on the IPOL lower-back trials (20 such starts in 18 of 22 files), where the
  /// first heel strike's loading, its step shorter than the walk's, is 0.47-1.1 of them. 0: off.
  double first_step_fraction = 0.4;
  /// The steps it is compared with: three, so that one odd step (a turn's, one missed) does not
  /// decide (at most kBodyHeld - 2).
  int first_step_followers = 3;
  /// A walk's leading rises judged so (the weight shift and the push: two).
  int first_steps_judged = 2;
  /// Body: the closing step (above). 0: off.
  double closing_rise_m_s2 = 0.2;  ///< smallest rise of the closing step, m/s^2
  double closing_rise_s = 0.1;     ///< ...at least as steep as that in this long, s
  double rest_band_m_s2 = 0.2;     ///< the trunk at rest: the vertical within this band, m/s^2
  double rest_s = 0.5;             ///< ...for this long, s
};
class GaitPhaseStepDetector final : public StepDetector {
 public:
  using Params = GaitPhaseStepParams;
  explicit GaitPhaseStepDetector(Params params = {});
  void reset() override;
  [[nodiscard]] std::string_view name() const override { return "gait-phase"; }
  [[nodiscard]] const StepDiagnostics& diagnostics() const override { return diag_; }

 private:
  /// `event.t_s` is the time the step happened (the heel strike), up to ~0.4 s before the
  /// sample that confirmed it; on the body, a walk's first steps up to its fourth step later.
  bool on_sample(const ImuSample& sample, StepEvent& event) override;
  /// Body: the steps still held (a walk's first and those after it) at the end of the stream.
  bool on_flush(StepEvent& event) override;
  bool update_foot(const ImuSample& s, double dt, StepEvent& event);
  bool update_body(const ImuSample& s, double dt, StepEvent& event);
  bool emit(double t_s, StepEvent& event);
  /// Body: the low-pass's delay (s) at the step frequency of an interval (s) between peaks.
  [[nodiscard]] double vertical_delay_s(double interval_s) const;
  /// Body: a step found (its time, its peak), the first of a walk or not.
  void hold_body_step(double t_s, double peak_m_s2, bool first_of_walk);
  /// Body: the first step held, judged against the ones after it (dropped or kept).
  void judge_first_body_step(bool again);
  /// Body: a step was counted at the vertical v: the next rise and fall start from here.
  void restart_after_step(double v, double t_s);
  /// Body: the walk's closing step is to be counted now.
  [[nodiscard]] bool closing_step_due(double t_s) const;
  /// Body: the oldest held step that may go, as `event`.
  bool release_body_step(StepEvent& event);
  /// Foot: the heel strike of the swing just ended, or -1 when the rate about the medio-lateral
  /// axis never reversed; `toes_up` is the sense of this swing's largest run (the axis or its
  /// opposite).
  [[nodiscard]] double heel_strike_t_s(Eigen::Vector3d& toes_up) const;

  Params params_;
  StepDiagnostics diag_;
  LowPass2 rate_lp_;
  OwnGravity g_;                   ///< learnt while the foot does not turn
  double force_moved_t_s_ = -1e9;  ///< last sample whose ||f| - g| was stance_acc_m_s2 or more
  LowPass2 vertical_lp_;
  bool have_t_ = false;
  double last_t_s_ = 0.0;
  double last_step_t_s_ = -1e9;
  bool have_step_ = false;
  // Foot: the swing in progress.
  bool in_swing_ = false;
  double swing_peak_rad_s_ = 0.0;
  double swing_angle_rad_ = 0.0;
  double swing_acc_m_s2_ = 0.0;
  double landing_t_s_ = 0.0;
  /// The swing's samples (rate, |f|) in a ring: the heel strike is sought at its end.
  static constexpr std::size_t kSwingCapacity = 512;  ///< 1.3 s at 400 Hz, 5 s at 100 Hz
  std::array<double, kSwingCapacity> swing_t_s_{};
  std::array<Eigen::Vector3d, kSwingCapacity> swing_gyro_rad_s_{};
  std::array<double, kSwingCapacity> swing_force_m_s2_{};
  std::size_t swing_head_ = 0;  ///< oldest sample of the ring
  std::size_t swing_size_ = 0;
  Eigen::Matrix3d swing_cov_ = Eigen::Matrix3d::Zero();  ///< sum of w w^T over the swing
  /// The steps' swings, each of unit trace, forgotten by `axis_keep` a step: the foot's
  /// medio-lateral axis in the sensor frame is its principal direction.
  Eigen::Matrix3d axis_cov_ = Eigen::Matrix3d::Zero();
  /// The sense of the swings' largest runs about that axis (toes up), forgotten as it is.
  Eigen::Vector3d toes_up_ = Eigen::Vector3d::Zero();
  double cycle_s_ = 0.0;  ///< recent interval between this foot's steps (0: none since a pause)
  // Body: gravity in the sensor frame and the oscillation's extremes.
  Eigen::Vector3d gravity_m_s2_ = Eigen::Vector3d::Zero();
  bool have_gravity_ = false;
  bool rising_ = false;  ///< after a valley, seeking the peak
  double valley_m_s2_ = 1e9;
  double peak_m_s2_ = -1e9;
  double peak_t_s_ = 0.0;
  double amplitude_m_s2_ = 0.0;   ///< recent peak-to-valley (0: none since the last pause)
  double step_interval_s_ = 0.0;  ///< the last step's interval (0: a walk's first)
  /// Body: a rise of the vertical, from the lowest point since the last step.
  struct BodyRise {
    double valley_m_s2 = 1e9;
    double valley_t_s = 0.0;
    double top_m_s2 = -1e9;
    double steepest_m_s3 = 0.0;  ///< its steepest slope
    double steepest_t_s = 0.0;   ///< ...and when
    /// A rise starting at the vertical v (m/s^2) at t_s.
    static BodyRise at(double v, double t_s) {
      return {.valley_m_s2 = v, .valley_t_s = t_s, .top_m_s2 = v};
    }
  };
  BodyRise rise_;              ///< the rise in progress
  BodyRise rise_before_rest_;  ///< the rise as the vertical last entered a standing band
  double last_v_m_s2_ = 0.0;
  double rest_lo_m_s2_ = 0.0;  ///< the band the vertical has stayed in since rest_since_t_s_
  double rest_hi_m_s2_ = 0.0;
  double rest_since_t_s_ = 0.0;
  bool closed_ = false;  ///< the walk's closing step has been counted
  /// Body: steps found and not yet reported, in order, each with its peak (m/s^2); the oldest
  /// is a walk's first under judgement while judging_first_.
  static constexpr std::size_t kBodyHeld = 8;
  HeldSteps<double, kBodyHeld> body_held_;
  bool judging_first_ = false;
  int first_drops_ = 0;  ///< a walk's leading steps dropped so far
};

}  // namespace telltale::fusion
