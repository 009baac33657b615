#include "telltale/fusion/gait_phase_steps.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <span>

#include "telltale/fusion/small_median.hpp"

namespace telltale::fusion {

GaitPhaseStepDetector::GaitPhaseStepDetector(Params params)
    : params_(params), rate_lp_(params.rate_cutoff_hz), vertical_lp_(params.vertical_cutoff_hz) {}

void GaitPhaseStepDetector::reset() { *this = GaitPhaseStepDetector(params_); }

bool GaitPhaseStepDetector::on_sample(const ImuSample& s, StepEvent& event) {
  const double dt = gate(s, have_t_, last_t_s_, diag_);
  if (dt < 0.0) return false;
  if (params_.mount == StepMount::kFoot && s.gyro_body_rad_s.allFinite()) {
    diag_.gyro_used = true;
    return update_foot(s, dt, event);
  }
  // No gyro on a foot: the trunk rule on the foot's vertical force still sees one rise and fall
  // per swing (lift, impact) -- a fallback, not the detector's purpose.
  diag_.gyro_used = false;
  return update_body(s, dt, event);
}

bool GaitPhaseStepDetector::emit(double t_s, StepEvent& event) {
  event.t_s = t_s;
  event.interval_s = have_step_ ? t_s - last_step_t_s_ : 0.0;
  last_step_t_s_ = t_s;
  have_step_ = true;
  return true;
}

bool GaitPhaseStepDetector::update_foot(const ImuSample& s, double dt, StepEvent& event) {
  // |w| whatever the mounting; smoothed at 5 Hz so the zero crossing of the medio-lateral rate
  // between toe-off and swing (the other axes keep |w| up there) and the impact's ringing do
  // not split a swing, while a stance of 0.1 s still shows.
  const double w_raw = s.gyro_body_rad_s.norm();
  const double w = rate_lp_.step(w_raw, dt);
  // ||f| - g| against the accelerometer's own reading of gravity, learnt while the foot stands
  // still (a 2-6 % scale error, 0.2-0.6 m/s^2, is common), so that "still" means the same on
  // every sensor.
  const double f_norm = s.acc_body_m_s2.norm();
  const double acc = std::abs(f_norm - g_.g_m_s2);
  if (acc >= params_.stance_acc_m_s2) force_moved_t_s_ = s.t_s;
  if (!in_swing_) {
    // Learnt while the foot does not turn (not while its force is still: that is judged
    // against this g, and a sensor reading 20 % high would never seem still).
    if (w < params_.stance_abs_rad_s) g_.still(f_norm, dt, params_.g_tau_s);
    if (w <= params_.swing_enter_rad_s) return false;
    in_swing_ = true;
    swing_peak_rad_s_ = w;
    swing_angle_rad_ = 0.0;
    swing_acc_m_s2_ = 0.0;
    landing_t_s_ = s.t_s;
    swing_head_ = swing_size_ = 0;
    swing_cov_.setZero();
  }
  if (swing_size_ == kSwingCapacity) {  // the oldest samples go: the heel strike is at the end
    swing_head_ = (swing_head_ + 1) % kSwingCapacity;
    --swing_size_;
  }
  const std::size_t tail = (swing_head_ + swing_size_++) % kSwingCapacity;
  swing_t_s_[tail] = s.t_s;
  swing_gyro_rad_s_[tail] = s.gyro_body_rad_s;
  swing_force_m_s2_[tail] = f_norm;
  swing_cov_ += s.gyro_body_rad_s * s.gyro_body_rad_s.transpose();
  swing_angle_rad_ += w * dt;
  swing_peak_rad_s_ = std::max(swing_peak_rad_s_, w);
  if (w >= params_.landing_fraction * swing_peak_rad_s_) landing_t_s_ = s.t_s;
  // Stance: relative to this swing's own peak, because a brisk walker's stance still rolls at
  // 1-2 rad/s (10-20 % of a 10 rad/s swing), while the slowest first step peaks near 2 rad/s.
  const double stance =
      std::max(params_.stance_abs_rad_s, params_.stance_fraction * swing_peak_rad_s_);
  // The force counts only while the foot turns: a foot rolling over its toes (heel-off) turns
  // at |f| = g, and the smoothed rate lags into the push-off that follows; a swing both turns
  // and accelerates.
  if (w_raw >= stance) swing_acc_m_s2_ = std::max(swing_acc_m_s2_, acc);
  // Stance is the foot still: it neither turns nor accelerates. The rate alone does not say so:
  // late in a running swing the foot has stopped turning (level for the landing) while it still
  // decelerates at 3-6 g, and the slap at its landing then reads as a swing of its own; a foot
  // pivoting on its ball in a turn turns slowly while it is loaded and moving. In the air
  // ||f| - g| passes through 0 in a few ms; a foot flat on the ground holds it near 0 once the
  // impact has rung out.
  if (w >= stance || s.t_s - force_moved_t_s_ < params_.stance_hold_s) return false;
  in_swing_ = false;
  const bool turned = swing_angle_rad_ >= params_.min_swing_deg * M_PI / 180.0 &&
                      swing_peak_rad_s_ >= params_.min_peak_rad_s;
  if (!turned || swing_acc_m_s2_ < params_.min_acc_m_s2) {
    ++diag_.rejected_amplitude;
    return false;
  }
  // One foot steps once per gait cycle: a second swing sooner than `interval_fraction` of the
  // recent cycle is the same step in two motions (heel-off then swing, or a landing that
  // settles); the cycle is forgotten after a pause, so a new walk at any pace starts afresh.
  // The spacing is between the steps' times: the heel strike, or the landing of a swing whose
  // rate never reversed. The landing alone (the last moment the rate was half the swing's peak)
  // is no fixed phase of the cycle: early in a swing whose peak is the toe-off's burst (a jog),
  // late in one that turns as fast through the swing (a walk), so at a change of pace two
  // landings came 0.5 s apart for heel strikes 0.82 s apart.
  Eigen::Vector3d toes_up = Eigen::Vector3d::Zero();
  const double hs = params_.report_heel_strike ? heel_strike_t_s(toes_up) : -1.0;
  const double trace = swing_cov_.trace();
  if (trace > 0.0) axis_cov_ = params_.axis_keep * axis_cov_ + swing_cov_ / trace;
  toes_up_ = params_.axis_keep * toes_up_ + toes_up;
  const double t_step = hs >= 0.0 ? hs : landing_t_s_;
  const double since = t_step - last_step_t_s_;
  if (since > params_.pause_s) cycle_s_ = 0.0;
  if (have_step_ &&
      since < std::max(params_.min_step_interval_s, params_.interval_fraction * cycle_s_)) {
    ++diag_.rejected_timing;
    return false;
  }
  if (have_step_ && since <= params_.pause_s)
    cycle_s_ = cycle_s_ > 0.0 ? cycle_s_ + 0.3 * (since - cycle_s_) : since;
  return emit(t_step, event);
}

double GaitPhaseStepDetector::heel_strike_t_s(Eigen::Vector3d& toes_up) const {
  // Toes down at push-off, toes up through the swing (the largest rotation of the cycle), toes
  // down again as the heel is lowered: the swing's end is where the rate about the medio-lateral
  // axis leaves the sign of the toes-up run that turned the foot through the largest angle. The
  // heel then meets the ground: the impact is the largest |f| shortly after (the annotated heel
  // strikes of the IPOL recordings are 0.02-0.08 s after the reversal).
  // Which sense is toes up: the sense of the swings' largest runs, learnt over the steps
  // (`toes_up_`), because a swing that begins with a pivot on the ball of the foot in a turn
  // turns the foot the other way first, sometimes further than the swing itself (IPOL 2-3_lf at
  // 18.1-18.9 s), and that run ends at the toe-off. Until the swings have agreed on it
  // (`toes_up_sure`: a walk's first step from standing can roll the foot further over its toes
  // than it swings), the largest run of either sense.
  toes_up.setZero();
  if (swing_size_ < 3) return -1.0;
  const double trace = swing_cov_.trace();
  const Eigen::Matrix3d cov =
      trace > 0.0 ? Eigen::Matrix3d(axis_cov_ + swing_cov_ / trace) : axis_cov_;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  Eigen::Vector3d axis = eig.eigenvectors().col(2);  // the largest eigenvalue's
  if (axis.dot(toes_up_) < 0.0) axis = -axis;
  const bool sense_known = axis.dot(toes_up_) >= params_.toes_up_sure;
  const auto at = [this](std::size_t i) { return (swing_head_ + i) % kSwingCapacity; };
  double best = 0.0, largest = 0.0, area = 0.0;
  std::size_t best_last = swing_size_;  // last sample of the largest toes-up run
  int sign = 0;
  const auto end_run = [&](std::size_t last) {
    if (std::abs(area) > std::abs(largest)) largest = area;
    if ((!sense_known || area > 0.0) && std::abs(area) > best) {
      best = std::abs(area);
      best_last = last;
    }
  };
  for (std::size_t i = 0; i < swing_size_; ++i) {
    const double p = swing_gyro_rad_s_[at(i)].dot(axis);
    const int sg = p > 0.0 ? 1 : p < 0.0 ? -1 : sign;
    if (sg != sign) {
      if (sign != 0) end_run(i - 1);
      sign = sg;
      area = 0.0;
    }
    if (i > 0) area += p * (swing_t_s_[at(i)] - swing_t_s_[at(i - 1)]);
  }
  end_run(swing_size_ - 1);  // the run still going: no reversal after it in this swing
  if (largest != 0.0) toes_up = largest > 0.0 ? axis : Eigen::Vector3d(-axis);
  if (best_last + 1 >= swing_size_) return -1.0;  // never reversed
  const std::size_t a = at(best_last), b = at(best_last + 1);
  const double pa = swing_gyro_rad_s_[a].dot(axis), pb = swing_gyro_rad_s_[b].dot(axis);
  const double f = pa != pb ? pa / (pa - pb) : 0.0;
  const double t_rev = swing_t_s_[a] + f * (swing_t_s_[b] - swing_t_s_[a]);
  double peak = -1.0, t_impact = t_rev;
  for (std::size_t i = best_last + 1; i < swing_size_; ++i) {
    const std::size_t k = at(i);
    if (swing_t_s_[k] > t_rev + params_.impact_window_s) break;
    if (swing_force_m_s2_[k] > peak) {
      peak = swing_force_m_s2_[k];
      t_impact = swing_t_s_[k];
    }
  }
  return t_impact;
}

bool GaitPhaseStepDetector::update_body(const ImuSample& s, double dt, StepEvent& event) {
  // Gravity in the sensor frame: the specific force averaged over ~1 s (several steps, whose
  // accelerations average out); vertical acceleration = the force along it minus its size.
  if (!have_gravity_) {
    gravity_m_s2_ = s.acc_body_m_s2;
    have_gravity_ = true;
  }
  const double k = dt > 0.0 ? dt / (params_.gravity_tau_s + dt) : 1.0;
  gravity_m_s2_ += k * (s.acc_body_m_s2 - gravity_m_s2_);
  const double g = gravity_m_s2_.norm();
  if (!(g > 1e-6)) return release_body_step(event);
  const double v = vertical_lp_.step(s.acc_body_m_s2.dot(gravity_m_s2_) / g - g, dt);

  // The hysteresis follows the walk (a ripple between two steps is under a fifth of a step's
  // swing) but not so closely that the closing step of a walk, whose trunk swings a third of
  // the walk's as it stops, is taken for a ripple; after a pause only the floor applies.
  if (s.t_s - last_step_t_s_ > params_.pause_s) amplitude_m_s2_ = 0.0;
  // The closing step (GaitPhaseStepParams): the rise since the lowest point after the last step
  // (its size, its steepest slope and when), as it was when the vertical last entered the band
  // it has stayed in since.
  if (v < rise_.valley_m_s2) {
    rise_ = BodyRise::at(v, s.t_s);
  } else {
    rise_.top_m_s2 = std::max(rise_.top_m_s2, v);
    const double slope = dt > 0.0 ? (v - last_v_m_s2_) / dt : 0.0;
    if (slope > rise_.steepest_m_s3) {
      rise_.steepest_m_s3 = slope;
      rise_.steepest_t_s = s.t_s;
    }
  }
  last_v_m_s2_ = v;
  if (v < rest_lo_m_s2_ || v > rest_hi_m_s2_) {
    rest_lo_m_s2_ = std::min(rest_lo_m_s2_, v);
    rest_hi_m_s2_ = std::max(rest_hi_m_s2_, v);
    if (rest_hi_m_s2_ - rest_lo_m_s2_ > params_.rest_band_m_s2) {
      rest_lo_m_s2_ = rest_hi_m_s2_ = v;
      rest_since_t_s_ = s.t_s;
      rise_before_rest_ = rise_;
    }
  }
  if (closing_step_due(s.t_s)) {
    // Counted as the trunk comes to rest, rest_s after the heel strike; a walk resumed before
    // that (the trunk never at rest) goes on under the rules below. The heel strike ended the
    // fall: it is the lowest point, less the low-pass's delay at the walk's step frequency.
    const BodyRise r = rise_before_rest_;
    restart_after_step(v, s.t_s);
    closed_ = true;
    last_step_t_s_ = r.valley_t_s;
    hold_body_step(r.valley_t_s - vertical_delay_s(step_interval_s_), r.top_m_s2, false);
    return release_body_step(event);
  }
  const double h =
      std::max(params_.hysteresis_abs_m_s2, params_.hysteresis_fraction * amplitude_m_s2_);
  if (!rising_) {
    valley_m_s2_ = std::min(valley_m_s2_, v);
    if (v > valley_m_s2_ + h) {
      rising_ = true;
      peak_m_s2_ = v;
      peak_t_s_ = s.t_s;
    }
    return release_body_step(event);
  }
  if (v > peak_m_s2_) {
    peak_m_s2_ = v;
    peak_t_s_ = s.t_s;
  }
  if (v >= peak_m_s2_ - h) return release_body_step(event);
  // A rise and a fall of h each: one step, at its peak.
  const double swing = peak_m_s2_ - valley_m_s2_;
  restart_after_step(v, s.t_s);
  if (have_step_ && peak_t_s_ - last_step_t_s_ < params_.min_body_interval_s) {
    ++diag_.rejected_timing;
    return release_body_step(event);
  }
  amplitude_m_s2_ =
      amplitude_m_s2_ > 0.0 ? amplitude_m_s2_ + 0.3 * (swing - amplitude_m_s2_) : swing;
  // The peak is the low-passed signal's, which lags the trunk's by the filter's delay at the
  // step frequency: the step happened that much earlier (0.09 s at 2 steps/s), at its heel
  // strike (IPOL lower back: the median offset from the annotated heel strikes was +0.05 to
  // +0.18 s per file, -0.04 to +0.08 s with the delay taken off).
  const bool first = !have_step_ || peak_t_s_ - last_step_t_s_ > params_.pause_s;
  const double interval = first ? 0.0 : peak_t_s_ - last_step_t_s_;
  step_interval_s_ = interval;
  last_step_t_s_ = peak_t_s_;
  have_step_ = true;
  closed_ = false;
  hold_body_step(peak_t_s_ - vertical_delay_s(interval), peak_m_s2_, first);
  return release_body_step(event);
}

void GaitPhaseStepDetector::restart_after_step(double v, double t_s) {
  rising_ = false;
  valley_m_s2_ = v;
  // Both rises start here: a snapshot from before the step would make an old rise this walk's
  // closing step.
  rise_ = rise_before_rest_ = BodyRise::at(v, t_s);
}

bool GaitPhaseStepDetector::closing_step_due(double t_s) const {
  const BodyRise& r = rise_before_rest_;
  return params_.closing_rise_m_s2 > 0.0 && have_step_ && !closed_ &&
         t_s - last_step_t_s_ <= params_.pause_s && t_s - rest_since_t_s_ >= params_.rest_s &&
         r.top_m_s2 - r.valley_m_s2 >= params_.closing_rise_m_s2 &&
         r.steepest_m_s3 >= params_.closing_rise_m_s2 / params_.closing_rise_s &&
         r.steepest_t_s - last_step_t_s_ >= params_.min_body_interval_s;
}

double GaitPhaseStepDetector::vertical_delay_s(double interval_s) const {
  // LowPass2: two first-order lags of tau = 1 / (2 pi f_c), each delaying a sinusoid of angular
  // frequency w by atan(w tau) / w. A walk's first step has no interval yet: 2 steps/s.
  const double tau = 1.0 / (2.0 * M_PI * params_.vertical_cutoff_hz);
  const double period =
      interval_s > 0.0 ? std::clamp(interval_s, params_.min_body_interval_s, params_.pause_s) : 0.5;
  const double w = 2.0 * M_PI / period;
  return 2.0 * std::atan(w * tau) / w;
}

void GaitPhaseStepDetector::hold_body_step(double t_s, double peak_m_s2, bool first_of_walk) {
  // The ring never fills: every update releases a step once the first is judged, which is at
  // most first_step_followers + 1 <= kBodyHeld - 1 steps in, and steps are 0.25 s apart.
  // The walk before is over: its first step is judged on what it had.
  if (first_of_walk && judging_first_) judge_first_body_step(false);
  body_held_.push(t_s, peak_m_s2);
  if (first_of_walk && params_.mount == StepMount::kBody && params_.first_step_fraction > 0.0) {
    judging_first_ = true;
    first_drops_ = 0;
  }
}

void GaitPhaseStepDetector::judge_first_body_step(bool again) {
  judging_first_ = false;
  // The median peak of the steps after it (at most first_step_followers, all held).
  const std::size_t n = body_held_.size() - 1;
  if (n == 0) return;  // a lone step: nothing to compare it with
  std::array<double, kBodyHeld> peaks{};
  for (std::size_t i = 0; i < n && i < kBodyHeld; ++i) peaks[i] = body_held_.note(i + 1);
  const double median = small_median<kBodyHeld>(std::span<const double>(peaks.data(), n));
  if (body_held_.note(0) < params_.first_step_fraction * median) {
    ++diag_.rejected_amplitude;
    body_held_.drop_oldest();
    // The walk's next step is judged as its first was (the push after the weight shift), once
    // it has its followers, unless a new walk forced this judgement (`again` false).
    if (again && ++first_drops_ < params_.first_steps_judged && body_held_.size() > 1)
      judging_first_ = true;
  }
}

bool GaitPhaseStepDetector::release_body_step(StepEvent& event) {
  if (judging_first_) {
    // Judged once it has its followers, or once the walk has ended (a pause since the last
    // step): a walk of two or three steps is judged on those.
    const auto followers = static_cast<std::size_t>(
        std::clamp(params_.first_step_followers, 1, static_cast<int>(kBodyHeld) - 2));
    if (body_held_.size() > followers || last_t_s_ - last_step_t_s_ > params_.pause_s)
      judge_first_body_step(true);
    if (judging_first_) return false;
  }
  if (body_held_.size() == 0) return false;
  body_held_.release(event);
  return true;
}

bool GaitPhaseStepDetector::on_flush(StepEvent& event) {
  while (judging_first_) judge_first_body_step(true);
  return release_body_step(event);
}

}  // namespace telltale::fusion
