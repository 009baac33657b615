#include "telltale/fusion/pdr/trunk_motion.hpp"

#include <algorithm>
#include <cmath>

namespace telltale::fusion {

void TrunkMotion::add(double t_s, double vertical_m_s2, double yaw_rad) {
  t_[head_] = t_s;
  a_[head_] = vertical_m_s2;
  yaw_[head_] = yaw_rad;
  head_ = (head_ + 1) % kRing;
  count_ = std::min(count_ + 1, kRing);
}

TrunkStep TrunkMotion::step(double t0_s, double t1_s, double height_m) const {
  TrunkStep out;
  // The step's samples: those in (t0, t1], each the mean of the interval that ends at it, from
  // the last sample at or before t0 (its start, which must be held). Walk back from the newest.
  std::size_t n = 0, newest = 0;
  bool found_end = false, found_start = false;
  for (std::size_t k = 0; k < count_; ++k) {
    const std::size_t i = (head_ + kRing - 1 - k) % kRing;
    if (t_[i] <= t0_s) {
      found_start = true;
      break;
    }
    if (t_[i] <= t1_s) {
      if (!found_end) newest = k;
      found_end = true;
      ++n;
    }
  }
  if (n < 5 || !found_start) return out;
  const auto at = [&](std::size_t j) {  // j = 0: the start; 1..n: the step's samples
    return (head_ + kRing - 1 - (newest + n - j)) % kRing;
  };
  // Mean specific force over the step (each sample weighs its interval) and mean yaw (circular).
  double sum_adt = 0.0, sum_dt = 0.0, ys = 0.0, yc = 0.0;
  for (std::size_t j = 1; j <= n; ++j) {
    const std::size_t i = at(j);
    const double dt = t_[i] - t_[at(j - 1)];
    sum_adt += a_[i] * dt;
    sum_dt += dt;
    ys += std::sin(yaw_[i]);
    yc += std::cos(yaw_[i]);
  }
  const double mean_a = sum_adt / sum_dt;
  out.yaw_rad = std::atan2(ys, yc);
  // Over a step of a steady walk the trunk comes back to its vertical velocity and its height.
  // The first is why the mean force is taken off (v ends where it began); the second fixes the
  // velocity's unknown constant: the one whose time-weighted mean is zero (p ends where it
  // began). Rectangle rule: each sample is its interval's mean. Two passes, no scratch array.
  double v = 0.0, sum_vdt = 0.0;
  for (std::size_t j = 1; j <= n; ++j) {
    const double dt = t_[at(j)] - t_[at(j - 1)];
    v += (a_[at(j)] - mean_a) * dt;
    sum_vdt += v * dt;
  }
  const double mean_v = sum_vdt / sum_dt;
  double p = 0.0, lo = 0.0, hi = 0.0;
  v = 0.0;
  for (std::size_t j = 1; j <= n; ++j) {
    const double dt = t_[at(j)] - t_[at(j - 1)];
    v += (a_[at(j)] - mean_a) * dt;
    p += (v - mean_v) * dt;
    lo = std::min(lo, p);
    hi = std::max(hi, p);
  }
  const double h = hi - lo;
  const double leg = params_.leg_per_height * height_m;
  if (!(h > 0.0 && h < params_.max_excursion_per_leg * leg)) return out;
  out.length_m = 2.0 * std::sqrt(2.0 * leg * h - h * h) / (1.0 - params_.double_support);
  out.ok = true;
  return out;
}

}  // namespace telltale::fusion
