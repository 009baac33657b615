#pragma once
/// \file
/// The peak-valley step detector of seed 003, the phone's (any carry: hand, pocket, bag, swinging
/// arm): the input contract and the registry are in steps.hpp.

#include <array>
#include <cstddef>

#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {

/// Seed 003, eq. (12): peak then valley on the low-passed |f|. A peak counts when it exceeds the
/// mean of the previous step's peak and valley and the time since the previous peak exceeds the
/// time threshold; the following valley closes the step (the event is reported at the valley).
/// Interpretation (the paper leaves them open): the time threshold follows the cadence
/// (fraction of the recent interval, with an absolute floor); a peak-to-valley swing below
/// `min_swing_m_s2` is not a step (standing still); the reference mean decays toward the running
/// mean of the signal after a pause so a new walk at a lower intensity is picked up.
struct PeakValleyStepParams {
  double cutoff_hz = 3.0;              ///< low-pass on |f|, Hz (steps are 1-3.5 Hz)
  double min_interval_s = 0.25;        ///< absolute time threshold between peaks, s
  double min_interval_fraction = 0.5;  ///< time threshold relative to the recent interval
  double max_interval_s = 2.0;         ///< beyond this the step memory is reset, s
  double initial_interval_s = 0.5;     ///< cadence memory at start and after a pause, s
  double min_swing_m_s2 = 0.6;         ///< smallest peak-to-valley swing that is a step, m/s^2
  double valley_rise_fraction = 0.25;  ///< a valley is confirmed once |f| rises by this x swing
  /// A step is not counted when the sensor's mean orientation turned by more than this in a
  /// second (TiltWindow): the phone is being handled, not carried. Walking with a phone in the
  /// hand, a pocket, a bag, an armband or a swinging hand tilts that mean by 1-5 deg in the
  /// median second (Oxford traces: 90 % of steps under 12, 98 % under 32, the highest a bag's);
  /// handling it turns it by 40-130. Judged when the step is confirmed (the last second against
  /// the one before) and again a second later (the second after the step against the one before
  /// it, which sees a handling's first second): each step is reported a second after it is
  /// confirmed, with its own time, and flush() releases the last ones when the stream ends. A
  /// step that keeps a steady walk's rhythm counts however the phone tilts (a walker moving it
  /// from the hand to a pocket walks on): its interval and the last `rhythm_steps` intervals
  /// each within `rhythm_tolerance` of their mean (a steady pace varies by under 10 %; a
  /// pocket's left and right steps differ by more). 0 turns the rule off (no step held).
  double max_tilt_deg = 30.0;
  int rhythm_steps = 4;
  double rhythm_tolerance = 0.3;
};
class PeakValleyStepDetector final : public StepDetector {
 public:
  using Params = PeakValleyStepParams;
  explicit PeakValleyStepDetector(Params params = {});
  void reset() override;
  [[nodiscard]] std::string_view name() const override { return "peak-valley"; }
  [[nodiscard]] const StepDiagnostics& diagnostics() const override { return diag_; }

 private:
  bool on_sample(const ImuSample& sample, StepEvent& event) override;
  bool on_flush(StepEvent& event) override;
  Params params_;
  StepDiagnostics diag_;
  LowPass2 lp_;
  TiltWindow tilt_;
  enum class Phase { kSeekPeak, kSeekValley } phase_ = Phase::kSeekPeak;
  bool have_t_ = false;
  double last_t_s_ = 0.0;
  double mean_m_s2_ = kStandardGravity_m_s2;  ///< slow running mean of the filtered |f|
  double prev_peak_ = 0.0, prev_valley_ = 0.0;
  bool have_prev_ = false;
  double cand_peak_ = 0.0, cand_peak_t_s_ = 0.0;
  double valley_ = 0.0;
  double last_peak_t_s_ = -1e9;
  double last_step_t_s_ = -1e9;
  double interval_ema_s_ = 0.5;
  double y1_ = 0.0, y2_ = 0.0;
  int n_ = 0;
  static constexpr std::size_t kRhythmCapacity = 8;
  std::array<double, kRhythmCapacity> step_times_{};  ///< the last confirmed steps, ring
  std::size_t n_step_times_ = 0;                      ///< confirmed steps so far (ring index)
  // Steps held a second before they are reported (the handled-phone rule; FIFO ring).
  static constexpr double kHold_s = 1.0;
  /// Each with whether it kept a steady walk's rhythm when confirmed; 8 > 1 s / min_interval_s.
  HeldSteps<bool, 8> held_;
  [[nodiscard]] bool keeps_rhythm(double t_s) const;
  bool detect(const ImuSample& s, double dt, StepEvent& event, bool& steady);
};

}  // namespace telltale::fusion
