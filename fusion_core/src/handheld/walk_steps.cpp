#include "telltale/fusion/handheld/walk_steps.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/small_median.hpp"

namespace telltale::fusion {

int WalkStepDetector::update(const ImuSample& s, const Eigen::Vector3d& up) {
  auto& st = state_;
  // The vertical specific force, its mean over mean_s taken out.
  const double v = s.acc_body_m_s2.dot(up);
  if (st.size == State::kRing) {
    st.sum_v -= st.ring_v[st.head];
    st.head = (st.head + 1) % State::kRing;
    --st.size;
  }
  {
    const std::size_t i = (st.head + st.size) % State::kRing;
    st.ring_t[i] = s.t_s;
    st.ring_v[i] = v;
    st.sum_v += v;
    ++st.size;
  }
  while (st.size > 1 && s.t_s - st.ring_t[st.head] > params_.mean_s) {
    st.sum_v -= st.ring_v[st.head];
    st.head = (st.head + 1) % State::kRing;
    --st.size;
  }
  const double centred = v - st.sum_v / static_cast<double>(st.size);
  // Smoothed over smooth_s.
  constexpr std::size_t kSm = State::kSm;
  if (st.sm_size == kSm) {
    st.sm_sum -= st.sm_v[st.sm_head];
    st.sm_head = (st.sm_head + 1) % kSm;
    --st.sm_size;
  }
  {
    const std::size_t i = (st.sm_head + st.sm_size) % kSm;
    st.sm_t[i] = s.t_s;
    st.sm_v[i] = centred;
    st.sm_sum += centred;
    ++st.sm_size;
  }
  while (st.sm_size > 1 && s.t_s - st.sm_t[st.sm_head] >= params_.smooth_s) {
    st.sm_sum -= st.sm_v[st.sm_head];
    st.sm_head = (st.sm_head + 1) % kSm;
    --st.sm_size;
  }
  const double sm = st.sm_sum / static_cast<double>(st.sm_size);
  st.w2_sum += s.gyro_body_rad_s.squaredNorm();
  ++st.w2_n;

  int emitted = 0;
  // A pause: no candidate for pause_intervals step intervals.
  if (st.walking) {
    const double limit =
        std::max(std::min(params_.max_interval_s, params_.pause_intervals * st.interval_s),
                 params_.min_interval_s);
    // A peak found in the walk's rhythm and still awaiting its valley keeps the walk going: the
    // closing step's loading may settle slowly, its valley a second after its peak.
    const bool pending = st.have_peak && st.peak_t_s - st.last_cand_t_s <= limit;
    if (s.t_s - st.last_cand_t_s > limit && !pending) {
      st.walking = false;
      st.held_n = 0;
    }
  }
  // Peak, then a valley min_swing below it.
  if (st.have_prev >= 2) {
    const bool local_max = st.prev_s > st.prev2_s && st.prev_s >= sm && st.prev_s > 0.0;
    if (local_max && (!st.have_peak || st.prev_s > st.peak_v)) {
      st.have_peak = true;
      st.peak_t_s = st.prev_t_s;
      st.peak_v = st.prev_s;
      st.peak_up = up;
      st.min_since_peak = st.prev_s;
    }
    if (st.have_peak) {
      st.min_since_peak = std::min(st.min_since_peak, sm);
      if (st.peak_v - st.min_since_peak >= params_.min_swing_m_s2 && sm < 0.0) {
        Candidate c;
        c.t_s = st.peak_t_s;
        c.up = st.peak_up;
        c.peak_m_s2 = st.peak_v;
        c.gyro_ms = st.w2_n > 0 ? st.w2_sum / st.w2_n : 0.0;
        st.w2_sum = 0.0;
        st.w2_n = 0;
        st.have_peak = false;
        if (c.t_s - st.last_cand_t_s >= params_.min_interval_s) emitted = on_candidate(c);
      } else if (s.t_s - st.peak_t_s > params_.max_interval_s) {
        st.have_peak = false;  // no valley: not a step's bounce
      }
    }
  }
  st.prev2_s = st.prev_s;
  st.prev_s = sm;
  st.prev_t_s = s.t_s;
  st.have_prev = std::min(st.have_prev + 1, 2);
  return emitted;
}

int WalkStepDetector::on_candidate(const Candidate& c_in) {
  auto& st = state_;
  Candidate c = c_in;
  const double interval = c.t_s - st.last_cand_t_s;
  st.last_cand_t_s = c.t_s;
  const bool cadence = interval >= params_.min_interval_s && interval <= params_.max_interval_s;
  if (st.walking) {
    // The pause test in update() already ended a walk with a longer gap.
    if (cadence) {
      c.interval_s = interval;
      st.interval_s = 0.75 * st.interval_s + 0.25 * interval;
      out_[0] = c;
      return 1;
    }
    st.walking = false;
    st.held_n = 0;
  }
  bool extends = cadence && st.held_n > 0;
  if (extends && st.held_n > 1) {
    const double prev = st.held[static_cast<std::size_t>(st.held_n - 1)].interval_s;
    extends = interval <= params_.max_interval_ratio * prev &&
              prev <= params_.max_interval_ratio * interval;
    if (!extends) {
      // Out of the rhythm of the candidates before the last one, but a walking interval after
      // it: a run may begin at the last one (a bounce of the hand while standing, then the
      // walk's first step a second later, then its steps).
      st.held[0] = st.held[static_cast<std::size_t>(st.held_n - 1)];
      st.held[0].interval_s = 0.0;
      st.held_n = 1;
      extends = true;
    }
  }
  if (!extends) {
    st.held_n = 0;
    c.interval_s = 0.0;
  } else {
    c.interval_s = interval;
  }
  if (st.held_n == kMaxHeld) {
    std::copy(st.held.begin() + 1, st.held.end(), st.held.begin());
    --st.held_n;
  }
  st.held[static_cast<std::size_t>(st.held_n++)] = c;
  if (st.held_n >= params_.confirm_steps && run_is_walk()) {
    st.walking = true;
    double sum = 0.0;
    for (int i = 1; i < st.held_n; ++i) sum += st.held[static_cast<std::size_t>(i)].interval_s;
    st.interval_s = sum / (st.held_n - 1);
    // The push of gait initiation (Params): the run's first candidate against the median peak
    // of the three after it (a run confirmed on fewer is taken whole).
    int first = 0;
    if (st.held_n >= 4) {
      const std::array<double, 3> next = {st.held[1].peak_m_s2, st.held[2].peak_m_s2,
                                          st.held[3].peak_m_s2};
      first = st.held[0].peak_m_s2 < params_.first_step_fraction * small_median<3>(next) ? 1 : 0;
    }
    const int n = st.held_n - first;
    std::copy(st.held.begin() + first, st.held.begin() + st.held_n, out_.begin());
    if (first == 1) out_[0].interval_s = 0.0;  // the walk's first step now
    st.held_n = 0;
    return n;
  }
  return 0;
}

bool WalkStepDetector::run_is_walk() const {
  const auto& st = state_;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double w2 = 0.0;
  for (int i = 0; i < st.held_n; ++i) {
    mean += st.held[static_cast<std::size_t>(i)].up;
    if (i > 0) w2 += st.held[static_cast<std::size_t>(i)].gyro_ms;
  }
  if (!(mean.norm() > 1e-9)) return false;
  mean.normalize();
  const double cos_max = std::cos(params_.max_tilt_deg * M_PI / 180.0);
  for (int i = 0; i < st.held_n; ++i)
    if (st.held[static_cast<std::size_t>(i)].up.dot(mean) < cos_max) return false;
  return std::sqrt(w2 / (st.held_n - 1)) < params_.max_gyro_rms_rad_s;
}

}  // namespace telltale::fusion
