// Fault monitor of the heading fusion: decides M_i (paper 002, eq. 16/20) per update.
#include "telltale/fusion/heading_monitor.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion {

const char* heading_sensor_status_name(HeadingSensorStatus s) {
  switch (s) {
    case HeadingSensorStatus::kNotConfigured:
      return "not_configured";
    case HeadingSensorStatus::kInUse:
      return "in_use";
    case HeadingSensorStatus::kNoReading:
      return "no_reading";
    case HeadingSensorStatus::kSampleRejected:
      return "sample_rejected";
    case HeadingSensorStatus::kInconsistent:
      return "inconsistent";
    case HeadingSensorStatus::kFrozen:
      return "frozen";
    case HeadingSensorStatus::kSilent:
      return "silent";
    case HeadingSensorStatus::kRecovering:
      return "recovering";
    case HeadingSensorStatus::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

void HeadingSensorMonitor::push_stat(SensorState& s, double stat) const {
  const int w = std::clamp(params_.window, 1, static_cast<int>(s.window.size()));
  s.window[static_cast<std::size_t>(s.window_pos)] =
      static_cast<float>(std::min(stat, params_.stat_cap));
  s.window_pos = (s.window_pos + 1) % w;
  s.window_fill = std::min(s.window_fill + 1, w);
  // Recomputed, not running: a running float sum would drift over a long session.
  double sum = 0.0;
  for (int k = 0; k < s.window_fill; ++k)
    sum += static_cast<double>(s.window[static_cast<std::size_t>(k)]);
  s.window_sum = sum;
}

void HeadingSensorMonitor::exclude(SensorState& s, HeadingSensorStatus why) const {
  s.excluded = true;
  s.reason = why;
  s.consistent = false;
  if (why == HeadingSensorStatus::kSilent) {
    // Its old statistics say nothing about the sensor that comes back.
    s.window_fill = 0;
    s.window_pos = 0;
    s.window_sum = 0.0;
  }
}

HeadingGateDecision HeadingSensorMonitor::assess(double t_s, double dt_s, int n,
                                                 const double* reading_deg, const double* r_deg2,
                                                 double pred_heading_deg, double pred_var_deg2,
                                                 HeadingSensorStatus* status) {
  HeadingGateDecision d;
  n = std::clamp(n, 0, kMaxHeadingSensors);
  if (!state_.started) {
    state_.started = true;
    state_.start_t_s = t_s;
  }
  std::array<double, kMaxHeadingSensors> nu{};
  std::array<bool, kMaxHeadingSensors> present{};
  int n_present = 0;
  for (int i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    SensorState& s = state_.sensors[ui];
    const double y = reading_deg[i];
    present[ui] = std::isfinite(y);
    if (!present[ui]) {
      status[i] = std::isinf(y) ? HeadingSensorStatus::kNonFinite : HeadingSensorStatus::kNoReading;
      const double since = s.ever_read ? s.last_reading_t_s : state_.start_t_s;
      if (params_.enabled && t_s - since > params_.silent_timeout_s &&
          !(s.excluded && s.reason == HeadingSensorStatus::kSilent)) {
        exclude(s, HeadingSensorStatus::kSilent);
      }
      if (s.excluded) status[i] = s.reason;
      continue;
    }
    ++n_present;
    if (params_.enabled && s.ever_read && t_s - s.last_reading_t_s > params_.silent_timeout_s &&
        !s.excluded) {
      exclude(s, HeadingSensorStatus::kSilent);  // came back after a gap nobody reported
    }
    if (!s.ever_read || y != s.last_value_deg) {
      s.last_value_deg = y;
      s.value_changed_t_s = t_s;
      s.fused_at_change_deg = state_.last_fused_deg;
    }
    s.last_reading_t_s = t_s;
    s.ever_read = true;
    nu[ui] = wrap_180_deg(y - pred_heading_deg);
  }
  if (!params_.enabled) {
    for (int i = 0; i < n; ++i) {
      if (present[static_cast<std::size_t>(i)]) {
        d.use_mask = static_cast<std::uint16_t>(d.use_mask | (1u << i));
        status[i] = HeadingSensorStatus::kInUse;
      }
    }
    return d;
  }
  if (n_present == 0) return d;

  // Frozen: the same value for frozen_timeout_s while the fused heading moved.
  for (int i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    SensorState& s = state_.sensors[ui];
    if (!present[ui] || (s.excluded && s.reason == HeadingSensorStatus::kFrozen)) continue;
    if (t_s - s.value_changed_t_s >= params_.frozen_timeout_s &&
        std::abs(wrap_180_deg(state_.last_fused_deg - s.fused_at_change_deg)) >=
            params_.frozen_motion_deg) {
      exclude(s, HeadingSensorStatus::kFrozen);
    }
  }

  // Candidates: present and not isolated. If none is left, the consensus of all present ones.
  std::array<int, kMaxHeadingSensors> cand{};
  int n_cand = 0;
  for (int i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (present[ui] && !state_.sensors[ui].excluded) cand[static_cast<std::size_t>(n_cand++)] = i;
  }
  bool any_healthy = false;  // not isolated, maybe just not reporting at this instant
  for (int i = 0; i < n; ++i)
    any_healthy = any_healthy || !state_.sensors[static_cast<std::size_t>(i)].excluded;
  if (n_cand == 0 && any_healthy) {
    // Healthy sensors exist but none reads now: fuse nothing, keep watching the isolated ones.
    for (int i = 0; i < n; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      if (!present[ui]) continue;
      SensorState& s = state_.sensors[ui];
      const double nu_i = nu[ui];
      s.last_stat = nu_i * nu_i / (std::max(pred_var_deg2, 0.0) + r_deg2[ui]);
      status[i] = s.consistent ? HeadingSensorStatus::kRecovering : s.reason;
    }
    return d;
  }
  if (n_cand == 0) {
    d.no_candidate = true;
    for (int i = 0; i < n; ++i) {
      if (present[static_cast<std::size_t>(i)]) cand[static_cast<std::size_t>(n_cand++)] = i;
    }
  }

  // Robust reference innovation.
  const double p = std::max(pred_var_deg2, 0.0);
  double nu_ref = 0.0;
  double r_ref = 0.0;
  if (n_present >= 3) {
    // Median over every sensor that reads now, isolated ones included: a sensor isolated by a
    // false alarm must be able to come back, and the median of three or more ignores any one
    // bad sensor whether or not it is isolated yet.
    std::array<double, kMaxHeadingSensors> v{};
    double r_sum = 0.0;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      if (!present[ui]) continue;
      v[static_cast<std::size_t>(m++)] = nu[ui];
      r_sum += r_deg2[ui];
    }
    for (int a = 1; a < m; ++a) {  // insertion sort: m <= 8 (std::sort trips -Warray-bounds)
      const double key = v[static_cast<std::size_t>(a)];
      int b = a - 1;
      while (b >= 0 && v[static_cast<std::size_t>(b)] > key) {
        v[static_cast<std::size_t>(b + 1)] = v[static_cast<std::size_t>(b)];
        --b;
      }
      v[static_cast<std::size_t>(b + 1)] = key;
    }
    const auto h = static_cast<std::size_t>(m / 2);
    nu_ref = (m % 2 == 1) ? v[h] : 0.5 * (v[h - 1] + v[h]);
    r_ref = r_sum / m;
  } else if (n_cand == 2) {
    const auto a = static_cast<std::size_t>(cand[0]);
    const auto b = static_cast<std::size_t>(cand[1]);
    const double za = nu[a] * nu[a] / (p + r_deg2[a]);
    const double zb = nu[b] * nu[b] / (p + r_deg2[b]);
    const std::size_t j = za <= zb ? a : b;  // the model breaks the tie
    const std::size_t o = j == a ? b : a;
    nu_ref = nu[j];
    r_ref = r_deg2[j];
    const double dz = (nu[o] - nu_ref) * (nu[o] - nu_ref) / (r_deg2[o] + r_ref);
    d.sensors_disagree = dz > params_.sample_gate;
  } else {
    const auto i = static_cast<std::size_t>(cand[0]);
    // Others healthy but not reporting at this instant (lower rates): test against the model
    // and wait for them rather than follow one reading. The only healthy sensor left is its own
    // reference unless it implies an impossible turn.
    bool others_healthy = false;
    for (int j = 0; j < n; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      others_healthy = others_healthy || (uj != i && !present[uj] && !state_.sensors[uj].excluded);
    }
    const double reach =
        params_.max_rate_deg_s * std::max(dt_s, 0.0) + 4.0 * std::sqrt(p + r_deg2[i]);
    if (!others_healthy && std::abs(nu[i]) <= reach) {
      nu_ref = nu[i];
      r_ref = r_deg2[i];
    } else {
      nu_ref = 0.0;
      r_ref = p;  // z = NIS against the model
    }
  }

  // Model test on the reference: a manoeuvre harder than Q allows (or a common-mode fault).
  if (nu_ref * nu_ref / (p + r_ref) > params_.model_gate) {
    d.model_mismatch = true;
    d.covariance_inflation = p > 0.0 ? std::max(1.0, (nu_ref * nu_ref - r_ref) / p) : 1.0;
  }

  for (int i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (!present[ui]) continue;
    SensorState& s = state_.sensors[ui];
    const double dnu = nu[ui] - nu_ref;
    const double z = dnu * dnu / (r_deg2[ui] + r_ref);
    s.last_stat = z;
    if (n_present == 2 && n_cand == 2 && !d.sensors_disagree && !d.no_candidate) {
      // Two that agree within noise: the model's choice of reference is a coin toss, so the
      // window gets half of their chi-square(1) each instead of all of it for one of them.
      const auto a = static_cast<std::size_t>(cand[0]);
      const auto b = static_cast<std::size_t>(cand[1]);
      const double dab = nu[a] - nu[b];
      push_stat(s, (ui == a || ui == b) ? 0.5 * dab * dab / (r_deg2[a] + r_deg2[b]) : z);
    } else {
      push_stat(s, z);
    }
    if (!s.excluded && s.window_sum > params_.exclude_threshold) {
      exclude(s, HeadingSensorStatus::kInconsistent);
    }
    if (s.excluded) {
      const bool stuck = t_s - s.value_changed_t_s >= params_.frozen_timeout_s &&
                         s.reason == HeadingSensorStatus::kFrozen;
      const bool ok = s.window_sum < params_.readmit_threshold && !stuck;
      if (ok && !s.consistent) s.consistent_since_s = t_s;
      s.consistent = ok;
      if (ok && t_s - s.consistent_since_s >= params_.readmit_hold_s) {
        s.excluded = false;
        s.consistent = false;
      }
    }
    const bool fusable = z <= params_.sample_gate;
    if (s.excluded && !d.no_candidate) {
      status[i] = s.consistent ? HeadingSensorStatus::kRecovering : s.reason;
    } else if (!fusable) {
      status[i] = HeadingSensorStatus::kSampleRejected;
    } else {
      status[i] = HeadingSensorStatus::kInUse;
      d.use_mask = static_cast<std::uint16_t>(d.use_mask | (1u << i));
    }
  }
  return d;
}

}  // namespace telltale::fusion
