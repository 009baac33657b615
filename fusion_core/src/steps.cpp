#include "telltale/fusion/steps.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "telltale/fusion/gait_phase_steps.hpp"
#include "telltale/fusion/peak_valley_steps.hpp"

namespace telltale::fusion {
namespace {

constexpr double kG = kStandardGravity_m_s2;

}  // namespace

double StepDetector::gate(const ImuSample& s, bool& have_t, double& last_t, StepDiagnostics& diag) {
  static constexpr ImuGateParams kGate{.gyro_required = false};
  const ImuGateResult g = gate_imu_sample(s, kGate, have_t, last_t, diag);
  return g.verdict == ImuVerdict::kReject ? -1.0 : g.dt_s;
}

// ---------------------------------------------------------------------------------------------
void SignedMeanWindow::reset() { *this = SignedMeanWindow(); }

void SignedMeanWindow::pop() {
  const double v = v_[head_];
  if (v > 0.0) {
    sum_pos_ -= v;
    n_pos_ -= 1.0;
  } else if (v < 0.0) {
    sum_neg_ -= v;
    n_neg_ -= 1.0;
  }
  head_ = (head_ + 1) % kCapacity;
  --size_;
}

void SignedMeanWindow::push(double t_s, double v, double window_s) {
  while (size_ > 0 && (size_ == kCapacity || t_[head_] < t_s - window_s)) pop();
  const std::size_t tail = (head_ + size_) % kCapacity;
  t_[tail] = t_s;
  v_[tail] = v;
  ++size_;
  if (v > 0.0) {
    sum_pos_ += v;
    n_pos_ += 1.0;
  } else if (v < 0.0) {
    sum_neg_ += v;
    n_neg_ += 1.0;
  }
  // Running sums drift by rounding over hours; resynchronise when the window empties of a sign.
  if (n_pos_ == 0.0) sum_pos_ = 0.0;
  if (n_neg_ == 0.0) sum_neg_ = 0.0;
}

double LowPass2::step(double x, double dt_s) {
  if (!init_ || !(dt_s > 0.0)) {
    y1_ = y2_ = x;
    init_ = true;
    return x;
  }
  const double tau = 1.0 / (2.0 * M_PI * cutoff_hz_);
  const double k = dt_s / (tau + dt_s);
  y1_ += k * (x - y1_);
  y2_ += k * (y1_ - y2_);
  return y2_;
}

// ---------------------------------------------------------------------------------------------
void TiltWindow::add(double t_s, const Eigen::Vector3d& f) {
  constexpr double kBlock_s = 1.0 / static_cast<double>(kBlocksPerSecond);
  if (!started_) {
    started_ = true;
    block_end_s_ = t_s + kBlock_s;
  }
  // Close every block this sample's time has passed (more than one across a gap: the skipped
  // ones stay empty), then add the sample to the open one. Each sample counts once: only the
  // direction of the sum is read, and a sample after a gap must not stand for the whole gap.
  for (std::size_t closed = 0; t_s >= block_end_s_; ++closed) {
    if (closed == kBlocks) {  // a gap longer than the window: start it again
      filled_ = 0;
      head_ = 0;
      block_end_s_ = t_s + kBlock_s;
      break;
    }
    const std::size_t slot = (head_ + filled_) % kBlocks;
    blocks_[slot] = current_;
    if (filled_ < kBlocks)
      ++filled_;
    else
      head_ = (head_ + 1) % kBlocks;
    current_.setZero();
    block_end_s_ += kBlock_s;
  }
  current_ += f;
}

double TiltWindow::angle_rad() const {
  // Until two seconds are in (the first moments after a start, when a phone is often still in
  // the hand), the blocks there are, split in halves.
  const std::size_t half = filled_ / 2;
  if (half == 0) return 0.0;
  const std::size_t first = head_ + filled_ - 2 * half;
  Eigen::Vector3d before = Eigen::Vector3d::Zero();
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < half; ++i) {
    before += blocks_[(first + i) % kBlocks];
    last += blocks_[(first + half + i) % kBlocks];
  }
  const double n = before.norm() * last.norm();
  if (!(n > 0.0)) return 0.0;
  return std::acos(std::clamp(before.dot(last) / n, -1.0, 1.0));
}

// ---------------------------------------------------------------------------------------------
AdaptiveStepDetector::AdaptiveStepDetector(Params params)
    : params_(params), acc_lp_(params.acc_cutoff_hz), gyro_lp_(params.gyro_cutoff_hz) {
  interval_ema_s_ = params_.initial_interval_s;
}

void AdaptiveStepDetector::reset() { *this = AdaptiveStepDetector(params_); }

std::array<double, 4> AdaptiveStepDetector::thresholds() const {
  return {std::max(acc_window_.positive_mean(), params_.acc_floor_m_s2),
          std::min(acc_window_.negative_mean(), -params_.acc_floor_m_s2),
          std::max(gyro_window_.positive_mean(), params_.gyro_floor_rad_s),
          std::min(gyro_window_.negative_mean(), -params_.gyro_floor_rad_s)};
}

bool AdaptiveStepDetector::on_sample(const ImuSample& s, StepEvent& event) {
  const double dt = gate(s, have_t_, last_t_s_, diag_);
  if (dt < 0.0) return false;
  const bool gyro_ok = params_.use_gyro && s.gyro_body_rad_s.allFinite();
  diag_.gyro_used = gyro_ok;

  // Dynamic specific force: |f| about its slow mean (absorbs accelerometer scale and bias, and
  // the fact that a foot's mean |f| over a cycle is above g).
  const double mag = s.acc_body_m_s2.norm();
  const double k_mean = dt > 0.0 ? dt / (params_.mean_tau_s + dt) : 1.0;
  g_est_m_s2_ += k_mean * (mag - g_est_m_s2_);
  const double a = acc_lp_.step(mag, dt) - g_est_m_s2_;
  acc_window_.push(s.t_s, a, params_.window_s);

  double w = 0.0;
  if (gyro_ok) {
    // The dominant rotation axis (the foot's pitch axis whatever the mounting): the axis with
    // the most angular-rate energy over ~2 s.
    const double k_e = dt > 0.0 ? dt / (2.0 + dt) : 1.0;
    gyro_energy_ += k_e * (s.gyro_body_rad_s.cwiseAbs2() - gyro_energy_);
    Eigen::Index axis = 0;
    gyro_energy_.maxCoeff(&axis);
    w = gyro_lp_.step(s.gyro_body_rad_s[axis], dt);
    gyro_window_.push(s.t_s, w, params_.window_s);
  }

  const auto th = thresholds();
  // Eq. (7): the four threshold conditions, each latched since the previous step.
  const bool now_a_hi = a > th[0];
  const bool now_a_lo = a < th[1];
  const bool now_w_hi = gyro_ok && w > th[2];
  const bool now_w_lo = gyro_ok && w < th[3];
  seen_[0] = seen_[0] || now_a_hi;
  seen_[1] = seen_[1] || now_a_lo;
  seen_[2] = seen_[2] || now_w_hi;
  seen_[3] = seen_[3] || now_w_lo;
  const bool all = seen_[0] && seen_[1] && (!gyro_ok || (seen_[2] && seen_[3]));

  // What closes a cycle (the paper's flow chart, Fig. 6, is not in the text; our reading):
  // - foot: the four excursions happen in swing, toe-off and heel strike, in an order that
  //   depends on the gait, and several of them twice per cycle; the one event that occurs once
  //   per cycle of that foot is the stance, so the step is confirmed when, after the four
  //   excursions, the foot has been at rest (|f| near g, |w| small) for `stance_s`;
  // - body: the trunk's vertical force goes once above and once below its mean per step, so the
  //   step is confirmed at the first sample below the lower threshold after the upper one.
  bool close = false;
  if (params_.require_stance) {
    const double quiet_a = std::max(params_.stance_fraction * th[0], params_.acc_floor_m_s2);
    const double quiet_w = std::max(params_.stance_fraction * th[2], params_.gyro_floor_rad_s);
    const bool quiet =
        std::abs(mag - kG) < quiet_a && (!gyro_ok || s.gyro_body_rad_s.norm() < quiet_w);
    if (!quiet) {
      quiet_since_s_ = -1.0;
    } else if (quiet_since_s_ < 0.0) {
      quiet_since_s_ = s.t_s;
    }
    close = all && quiet_since_s_ >= 0.0 && s.t_s - quiet_since_s_ >= params_.stance_s;
  } else {
    close = all && now_a_lo;
  }
  if (!close) return false;

  // Time thresholds: never faster than the absolute limit, nor than a fraction of the recent
  // interval; after a long pause the cadence memory restarts.
  const double since = s.t_s - last_step_t_s_;
  if (since > params_.max_interval_s) interval_ema_s_ = params_.initial_interval_s;
  const double t_min =
      std::max(params_.min_interval_s, params_.min_interval_fraction * interval_ema_s_);
  seen_ = {};
  if (since < t_min) {
    ++diag_.rejected_timing;
    return false;
  }
  if (have_step_ && since <= params_.max_interval_s)
    interval_ema_s_ += 0.3 * (since - interval_ema_s_);
  event.t_s = s.t_s;
  event.interval_s = have_step_ ? since : 0.0;
  last_step_t_s_ = s.t_s;
  have_step_ = true;
  return true;
}

// ---------------------------------------------------------------------------------------------
PeakStepDetector::PeakStepDetector(Params params) : params_(params), lp_(params.cutoff_hz) {}

void PeakStepDetector::reset() { *this = PeakStepDetector(params_); }

bool PeakStepDetector::on_sample(const ImuSample& s, StepEvent& event) {
  bool have_t = n_ > 0;
  const double dt = gate(s, have_t, last_t_s_, diag_);
  if (dt < 0.0) return false;
  const double y = lp_.step(s.acc_body_m_s2.norm(), dt);
  bool step = false;
  if (n_ >= 2 && y1_ > y2_ && y1_ >= y && y1_ > params_.min_height_m_s2) {
    if (t1_ - last_step_t_s_ >= params_.min_distance_s) {
      event.t_s = t1_;
      event.interval_s = last_step_t_s_ > -1e8 ? t1_ - last_step_t_s_ : 0.0;
      last_step_t_s_ = t1_;
      step = true;
    } else {
      ++diag_.rejected_timing;
    }
  }
  y2_ = y1_;
  y1_ = y;
  t1_ = s.t_s;
  n_ = std::min(n_ + 1, 2);
  return step;
}

// ---------------------------------------------------------------------------------------------
FixedThresholdStepDetector::FixedThresholdStepDetector(Params params)
    : params_(params), lp_(params.cutoff_hz) {}

void FixedThresholdStepDetector::reset() { *this = FixedThresholdStepDetector(params_); }

bool FixedThresholdStepDetector::on_sample(const ImuSample& s, StepEvent& event) {
  const double dt = gate(s, have_t_, last_t_s_, diag_);
  if (dt < 0.0) return false;
  const double y = lp_.step(s.acc_body_m_s2.norm(), dt);
  if (!armed_) {
    if (y < params_.threshold_m_s2 - params_.hysteresis_m_s2) armed_ = true;
    return false;
  }
  if (y <= params_.threshold_m_s2) return false;
  armed_ = false;
  if (s.t_s - last_step_t_s_ < params_.refractory_s) {
    ++diag_.rejected_timing;
    return false;
  }
  event.t_s = s.t_s;
  event.interval_s = last_step_t_s_ > -1e8 ? s.t_s - last_step_t_s_ : 0.0;
  last_step_t_s_ = s.t_s;
  return true;
}

// ---------------------------------------------------------------------------------------------
bool SwingStepDetector::update(double t_s, const Eigen::Vector3d& w) {
  if (!std::isfinite(t_s) || !w.allFinite() || (have_t_ && !(t_s > last_t_s_))) return false;
  const double dt = have_t_ ? t_s - last_t_s_ : 0.0;
  last_t_s_ = t_s;
  have_t_ = true;
  // The swing axis: one power-iteration step a sample keeps it continuous (no sign flips) while
  // it follows the phone into another pose.
  const double keep = std::exp(-dt / params_.axis_tau_s);
  rate_cov_ = keep * rate_cov_ + (1.0 - keep) * w * w.transpose();
  const Eigen::Vector3d next = rate_cov_ * axis_;
  if (next.norm() > 1e-12) axis_ = next.normalized();
  return on_rate(t_s, dt, w.dot(axis_));
}

bool SwingStepDetector::on_rate(double t_s, double dt, double rate) {
  if (sign_ != 0 && t_s - since_s_ > params_.max_interval_s) {
    sign_ = 0;
    peak_ = sweep_rad_ = 0.0;
    done_sweeps_ = {};
  }
  const int sign = rate > 0.0 ? 1 : -1;
  const double mag = std::abs(rate);
  if (sign != run_sign_) run_rad_ = 0.0;  // the rate crossed zero
  run_sign_ = sign;
  run_rad_ += mag * dt;
  if (mag >= params_.min_rate_rad_s)
    slow_since_s_ = -1.0;
  else if (slow_since_s_ < 0.0)
    slow_since_s_ = t_s;
  if (sign == sign_) {
    peak_ = std::max(peak_, mag);
    sweep_rad_ += mag * dt;
  }
  const double half_sweep = 0.5 * params_.min_sweep_deg * M_PI / 180.0;
  if (swinging(t_s) && slow_since_s_ >= 0.0 && t_s - slow_since_s_ >= params_.rest_s &&
      sweep_rad_ >= half_sweep) {
    // Come to rest after half a swing: the walk's last step.
    const double rest_t_s = slow_since_s_;
    reset();
    last_t_s_ = t_s;
    have_t_ = true;
    step_t_s_ = rest_t_s;
    return true;
  }
  if (sign == sign_) return false;
  const double threshold = std::max(params_.min_rate_rad_s, params_.peak_fraction * peak_);
  if (mag < threshold) return false;
  if (sign_ != 0 && t_s - since_s_ < params_.min_interval_s) return false;  // a ripple
  // A new half swing: the phone has turned at an end of its swing, if the one that ended swept
  // an angle (a wobble before the first swing, or a hand's tremor, does not).
  const bool step = sign_ != 0 && sweep_rad_ >= half_sweep;
  if (sign_ != 0) half_swing_s_ = t_s - since_s_;
  done_sweeps_ = {sweep_rad_, done_sweeps_[0]};
  peak_ = mag;
  sweep_rad_ = run_rad_;  // this half swing since the rate crossed zero
  sign_ = sign;
  since_s_ = t_s;
  if (step) step_t_s_ = t_s;
  return step;
}

bool SwingStepDetector::swinging(double t_s) const {
  const double min_sweep = params_.min_sweep_deg * M_PI / 180.0;
  return sign_ != 0 && t_s - since_s_ < params_.max_interval_s &&
         std::min(done_sweeps_[0], done_sweeps_[1]) >= min_sweep;
}

// ---------------------------------------------------------------------------------------------
namespace {
constexpr std::array<std::string_view, 5> kNames = {"adaptive", "peak", "fixed-threshold",
                                                    "peak-valley", "gait-phase"};
}

std::span<const std::string_view> step_detector_names() { return kNames; }

std::string_view default_step_detector(StepMount mount) {
  // Foot: gait phases count the first step from standing and the closing step that the adaptive
  // thresholds miss (IPOL foot sensors). Body: peak-valley, which copes with a phone anywhere
  // (hand, bag, swinging arm: Oxford traces); a sensor rigid to the trunk (belt, lower back)
  // does better with gait-phase (see fusion_cli steps --mount body).
  return mount == StepMount::kFoot ? "gait-phase" : "peak-valley";
}

std::unique_ptr<StepDetector> make_step_detector(std::string_view name, StepMount mount) {
  const bool foot = mount == StepMount::kFoot;
  if (name == "adaptive") {
    AdaptiveStepParams p;
    if (!foot) {
      // A body-worn sensor rotates at the stride (half the step) frequency: its gyro conditions
      // would accept every other step only, so the body variant keeps the acceleration ones.
      p.use_gyro = false;
      p.require_stance = false;
      p.acc_cutoff_hz = 4.0;
      p.acc_floor_m_s2 = 0.4;
      p.min_interval_s = 0.22;
      p.initial_interval_s = 0.55;
      p.max_interval_s = 2.0;
    }
    return std::make_unique<AdaptiveStepDetector>(p);
  }
  if (name == "peak") {
    PeakStepParams p;
    if (foot) {
      p.min_height_m_s2 = 20.0;
      p.min_distance_s = 0.6;
    }
    return std::make_unique<PeakStepDetector>(p);
  }
  if (name == "fixed-threshold") {
    FixedThresholdStepParams p;
    if (foot) {
      p.threshold_m_s2 = 20.0;
      p.hysteresis_m_s2 = 3.0;
      p.refractory_s = 0.6;
    }
    return std::make_unique<FixedThresholdStepDetector>(p);
  }
  if (name == "peak-valley") {
    PeakValleyStepParams p;
    if (foot) {
      p.min_interval_s = 0.36;
      p.min_swing_m_s2 = 2.0;
      p.max_tilt_deg = 0.0;  // a foot turns through 30-100 deg in every swing
    }
    return std::make_unique<PeakValleyStepDetector>(p);
  }
  if (name == "gait-phase") {
    GaitPhaseStepParams p;
    p.mount = mount;
    return std::make_unique<GaitPhaseStepDetector>(p);
  }
  return nullptr;
}

}  // namespace telltale::fusion
