#include "telltale/fusion/peak_valley_steps.hpp"

#include <algorithm>
#include <cmath>

namespace telltale::fusion {

PeakValleyStepDetector::PeakValleyStepDetector(Params params)
    : params_(params), lp_(params.cutoff_hz) {
  interval_ema_s_ = params_.initial_interval_s;
}

bool PeakValleyStepDetector::keeps_rhythm(double t_s) const {
  const auto k = static_cast<std::size_t>(std::clamp(params_.rhythm_steps, 1, 7));
  if (n_step_times_ < k + 1) return false;
  const auto at = [&](std::size_t back) {  // back = 0: the last confirmed step
    return step_times_[(n_step_times_ - 1 - back) % kRhythmCapacity];
  };
  const double mean = (at(0) - at(k)) / static_cast<double>(k);
  const double lo = (1.0 - params_.rhythm_tolerance) * mean;
  const double hi = (1.0 + params_.rhythm_tolerance) * mean;
  const double gap = t_s - at(0);
  if (!(gap >= lo && gap <= hi)) return false;
  for (std::size_t i = 0; i < k; ++i) {
    const double iv = at(i) - at(i + 1);
    if (!(iv >= lo && iv <= hi)) return false;
  }
  return true;
}

void PeakValleyStepDetector::reset() { *this = PeakValleyStepDetector(params_); }

bool PeakValleyStepDetector::on_sample(const ImuSample& s, StepEvent& event) {
  const double dt = gate(s, have_t_, last_t_s_, diag_);
  if (dt < 0.0) return false;
  const bool rule = params_.max_tilt_deg > 0.0;
  if (rule) tilt_.add(s.t_s, s.acc_body_m_s2);
  bool steady = false;
  StepEvent found;
  const bool step = detect(s, dt, found, steady);
  if (!rule) {  // no handled-phone rule: every step at once
    if (step) event = found;
    return step;
  }
  // Each step is held for a second, then judged on the tilt across it: the mean specific force
  // of the second after it against that of the second before (the check in detect() saw only
  // the two seconds before it, so a handling's first second passed). A step of a steady walk's
  // rhythm passes as it did there.
  if (step) {
    // Full cannot happen (steps are >= min_interval_s apart); if it did, the oldest goes out
    // unchecked rather than lost.
    const bool reported = held_.full();
    if (reported) held_.release(event);
    held_.push(found.t_s, steady);
    if (reported) return true;
  }
  const double max_tilt_rad = params_.max_tilt_deg * (M_PI / 180.0);
  while (held_.size() > 0 && s.t_s - held_.t_s(0) >= kHold_s) {
    if (held_.note(0) || !(tilt_.angle_rad() > max_tilt_rad)) {
      held_.release(event);
      return true;
    }
    ++diag_.rejected_handling;
    held_.drop_oldest();
  }
  return false;
}

bool PeakValleyStepDetector::on_flush(StepEvent& event) {
  // The stream has ended: the second after a held step is not all there, and the check before
  // it was made. Release as it is.
  if (held_.size() == 0) return false;
  held_.release(event);
  return true;
}

bool PeakValleyStepDetector::detect(const ImuSample& s, double dt, StepEvent& event, bool& steady) {
  const double y = lp_.step(s.acc_body_m_s2.norm(), dt);
  const double k_mean = dt > 0.0 ? dt / (2.0 + dt) : 1.0;
  mean_m_s2_ = n_ == 0 ? y : mean_m_s2_ + k_mean * (y - mean_m_s2_);
  const bool is_max = n_ >= 2 && y1_ > y2_ && y1_ >= y;
  const bool is_min = n_ >= 2 && y1_ < y2_ && y1_ <= y;
  const double t1 = s.t_s - dt;  // time of the extremum (previous sample)
  const double y_ext = y1_;
  y2_ = y1_;
  y1_ = y;
  n_ = std::min(n_ + 1, 2);

  // After a pause the previous step no longer describes the gait: forget it.
  if (have_prev_ && s.t_s - last_step_t_s_ > params_.max_interval_s) {
    have_prev_ = false;
    interval_ema_s_ = params_.initial_interval_s;
  }
  if (phase_ == Phase::kSeekPeak) {
    if (!is_max) return false;
    // Eq. (12), first condition: the peak exceeds the mean of the previous peak and valley.
    const double ref = have_prev_ ? 0.5 * (prev_peak_ + prev_valley_) : mean_m_s2_;
    if (!(y_ext > ref) || !(y_ext > mean_m_s2_)) return false;
    // Second condition: the time since the previous peak exceeds the time threshold.
    const double t_th =
        std::max(params_.min_interval_s, params_.min_interval_fraction * interval_ema_s_);
    if (t1 - last_peak_t_s_ < t_th) {
      ++diag_.rejected_timing;
      return false;
    }
    cand_peak_ = y_ext;
    cand_peak_t_s_ = t1;
    valley_ = y_ext;
    phase_ = Phase::kSeekValley;
    return false;
  }
  // Seeking the valley that closes the step.
  if (is_max && y_ext > cand_peak_) {  // a higher peak before any valley: it is the real peak
    cand_peak_ = y_ext;
    cand_peak_t_s_ = t1;
    valley_ = y_ext;
    return false;
  }
  valley_ = std::min(valley_, y);
  if (s.t_s - cand_peak_t_s_ > params_.max_interval_s) {  // no valley: not a step
    ++diag_.rejected_amplitude;
    phase_ = Phase::kSeekPeak;
    return false;
  }
  const double swing = cand_peak_ - valley_;
  const bool risen = y - valley_ > params_.valley_rise_fraction * swing;
  if (!risen) return false;
  if (swing < params_.min_swing_m_s2 || !(valley_ < mean_m_s2_)) {
    if (is_min) {  // a shallow dip: keep waiting for the real valley unless too late
      ++diag_.rejected_amplitude;
    }
    return false;
  }
  if (params_.max_tilt_deg > 0.0) {  // the handled-phone rule (its state kept only with it)
    steady = keeps_rhythm(s.t_s);
    if (!steady && tilt_.angle_rad() > params_.max_tilt_deg * (M_PI / 180.0)) {
      // The phone is being handled: its swing is the hand's, not a step's. Not a step, and
      // nothing learnt from it.
      ++diag_.rejected_handling;
      phase_ = Phase::kSeekPeak;
      return false;
    }
    step_times_[n_step_times_ % kRhythmCapacity] = s.t_s;
    ++n_step_times_;
  }
  const double since = cand_peak_t_s_ - last_peak_t_s_;
  if (have_prev_ && since > 0.0 && since < params_.max_interval_s)
    interval_ema_s_ += 0.3 * (since - interval_ema_s_);
  event.t_s = s.t_s;
  event.interval_s = have_prev_ ? s.t_s - last_step_t_s_ : 0.0;
  prev_peak_ = cand_peak_;
  prev_valley_ = valley_;
  have_prev_ = true;
  last_peak_t_s_ = cand_peak_t_s_;
  last_step_t_s_ = s.t_s;
  phase_ = Phase::kSeekPeak;
  return true;
}

}  // namespace telltale::fusion
