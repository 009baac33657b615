#include "telltale/fusion/pdr/cadence.hpp"

#include <algorithm>

namespace telltale::fusion {

void Cadence::at_step(double t_s, double per_event, bool learn) {
  if (learn && last_step_t_s_ >= 0.0) {
    const double interval = (t_s - last_step_t_s_) / per_event;
    if (interval >= min_interval_s_ && interval < 2.0) learn_interval(interval);
  }
  last_step_t_s_ = t_s;
}

void Cadence::forget() {
  interval_s_ = 0.0;
  interval_count_ = 0;
}

void Cadence::learn_interval(double interval_s) {
  // A median, not a running mean: a hand moving the phone makes events at any moment, and two
  // of them 0.3 s apart made the gap filler count 5 steps for a gap that held 3.
  for (std::size_t i = 0; i + 1 < kIntervals; ++i) intervals_[i] = intervals_[i + 1];
  intervals_.back() = interval_s;
  interval_count_ = std::min(interval_count_ + 1, kIntervals);
  // The newest interval_count_ of them, sorted by insertion (at most 5).
  std::array<double, kIntervals> sorted{};
  const std::size_t n = interval_count_;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = intervals_[kIntervals - n + i];
    std::size_t j = i;
    for (; j > 0 && sorted[j - 1] > v; --j) sorted[j] = sorted[j - 1];
    sorted[j] = v;
  }
  const std::size_t mid = n / 2;
  interval_s_ = n % 2 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
}

}  // namespace telltale::fusion
