#include "telltale/fusion/pdr/step_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace telltale::fusion {
namespace {

/// Slot of a (possibly negative) running index in a ring of n.
std::size_t ring_slot(std::int64_t id, std::size_t n) {
  const auto m = static_cast<std::int64_t>(n);
  return static_cast<std::size_t>(((id % m) + m) % m);
}

}  // namespace

StepGaps::StepGaps(Params params) : params_(params) {
  bin_id_.fill(std::numeric_limits<std::int64_t>::min());
}

int StepGaps::at_step(double t_s, const StepSource& source, double energy,
                      const RecentSamples& recent) {
  // Steps the detector missed: its thresholds follow the last steps' peaks and valleys, so after
  // an arm swing the smaller steps of the next pose go unseen until its memory resets (4-9
  // steps lost per arm-swing exit, measured; not always while a switch is detected). A gap of
  // about n step intervals while the phone kept moving like a walk (acceleration energy over
  // the last window) counts n - 1 more steps; a stop does not.
  int missed = 0;
  const double gap = t_s - last_step_t_s_;
  if (last_step_t_s_ >= 0.0 && interval_s_ > 0.0) {
    const double ratio = gap / interval_s_;
    if (ratio > params_.min_ratio && gap < params_.max_gap_s && energy > params_.min_energy &&
        !source.after_stand)
      missed = static_cast<int>(std::lround(ratio)) - 1;
  }
  // Filling in needs a cadence that was measured. A gap after every step is no missed step but a
  // cadence that is wrong (learnt from two detections of one step, or from a detector that has
  // since locked onto the stride): after kMaxFilledRow filled steps in a row the cadence is
  // learnt again from the gaps. (Learning it from the gaps divided by the steps filled into
  // them kept any wrong cadence for ever: 2 or 8 steps counted for every one.)
  constexpr int kMaxFilledRow = 10;
  filled_row_ = missed > 0 ? filled_row_ + 1 : 0;
  if (filled_row_ > kMaxFilledRow && !recent.walking_period(interval_s_)) {
    missed = 0;
    filled_row_ = 0;
    interval_s_ = 0.0;
    interval_count_ = 0;
  }
  end_gap(t_s, 1.0, missed == 0 && !source.handoff);
  return missed;
}

void StepGaps::learn_cadence(double t_s, double per_event) { end_gap(t_s, per_event, true); }

void StepGaps::end_gap(double t_s, double per_event, bool learn) {
  if (learn && last_step_t_s_ >= 0.0) {
    const double interval = (t_s - last_step_t_s_) / per_event;
    if (interval >= params_.min_interval_s && interval < 2.0) learn_interval(interval);
  }
  last_step_t_s_ = t_s;
}

void StepGaps::learn_interval(double interval_s) {
  // A median, not a running mean: a hand moving the phone makes events at any moment, and two
  // of them 0.3 s apart made the filler count 5 steps for a gap that held 3.
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

void StepGaps::add_heading(double t_s, const Eigen::Vector2d& unit) {
  const auto id = static_cast<std::int64_t>(std::floor(t_s / kHeadingBinS));
  const std::size_t slot = ring_slot(id, kHeadingBins);
  if (bin_id_[slot] != id) {
    bin_id_[slot] = id;
    bins_[slot].setZero();
  }
  bins_[slot] += unit;
}

Eigen::Vector2d StepGaps::gap_turn(double t0_s, double t1_s, int parts) const {
  const Eigen::Vector2d none(1.0, 0.0);
  if (parts < 2 || !(t1_s > t0_s) || t0_s < bins_from_t_s_ ||
      t1_s - t0_s > kHeadingBinS * static_cast<double>(kHeadingBins - 2))
    return none;
  // Each part's heading: the circular mean of the bins its interval covers.
  std::array<Eigen::Vector2d, kHeadingBins> part{};
  Eigen::Vector2d all = Eigen::Vector2d::Zero();
  const double span = (t1_s - t0_s) / parts;
  for (int j = 0; j < parts; ++j) {
    const double a = t0_s + j * span, b = a + span;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (auto id = static_cast<std::int64_t>(std::floor(a / kHeadingBinS));
         static_cast<double>(id) * kHeadingBinS < b; ++id) {
      const std::size_t slot = ring_slot(id, kHeadingBins);
      if (bin_id_[slot] == id) sum += bins_[slot];
    }
    if (!(sum.norm() > 1e-9)) return none;  // a part with no heading: no better than one
    part[static_cast<std::size_t>(j)] = sum.normalized();
    all += sum;
  }
  // Relative to the whole gap's mean: rotate each part's unit vector back by the mean's angle.
  const double mean = std::atan2(all.y(), all.x());
  Eigen::Vector2d turn = Eigen::Vector2d::Zero();
  for (int j = 0; j < parts; ++j) {
    const Eigen::Vector2d& u = part[static_cast<std::size_t>(j)];
    const double h = std::atan2(u.y(), u.x()) - mean;
    turn += Eigen::Vector2d(std::cos(h), std::sin(h));
  }
  return turn / parts;
}

}  // namespace telltale::fusion
