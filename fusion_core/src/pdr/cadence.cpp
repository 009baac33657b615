#include "telltale/fusion/pdr/cadence.hpp"

#include <algorithm>
#include <span>

#include "telltale/fusion/small_median.hpp"

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
  // The newest interval_count_ of them.
  interval_s_ = small_median<kIntervals>(std::span<const double>(intervals_).last(interval_count_));
}

}  // namespace telltale::fusion
