// The race scenario's boat: the course stepped on its own grid, smoothed for the rigid body
// (see race.hpp; the scenario itself is in scenarios.cpp beside the dinghy, whose waves it shares).
#include "telltale/fusion/sim/race.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion::sim {
namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

RaceCourse::RaceCourse(std::uint64_t seed, CourseParams params) : sim_(seed, params) {}

void RaceCourse::step() {
  const std::int64_t k = next_step_++;
  const double t = static_cast<double>(k) * kStepS;
  // Asked half a step after the step's time, CourseSim::at takes exactly one more step of its
  // 0.05 s: one receiver epoch per step, whatever the readers' own pace.
  Step s;
  s.state = sim_.at(t + 0.5 * kStepS);
  s.state.t_s = t;
  s.heading_deg = steps_.empty()
                      ? s.state.heading_deg
                      : steps_.back().heading_deg +
                            diff_180_deg(s.state.heading_deg, steps_.back().state.heading_deg);
  steps_.push_back(s);
  // Knot j sits on step 5 j; it is complete once the two steps after it are in (its speed mean).
  if (k >= 2 && (k - 2) % kKnotSteps == 0) {
    const std::int64_t j = (k - 2) / kKnotSteps;
    const std::int64_t centre = j * kKnotSteps;
    double sum = 0.0;
    int n = 0;
    for (std::int64_t i = std::max<std::int64_t>(centre - 2, first_step_); i <= k; ++i, ++n)
      sum += steps_[static_cast<std::size_t>(i - first_step_)].state.sog_m_s;
    const Step& c = steps_[static_cast<std::size_t>(centre - first_step_)];
    knots_.push_back({c.heading_deg * kDeg, sum / n, c.state.heel_deg * kDeg});
  }
  while (steps_.front().state.t_s < t - kHistoryS) {
    steps_.pop_front();
    ++first_step_;
  }
  while (!knots_.empty() && static_cast<double>(first_knot_) * kKnotS < t - kHistoryS) {
    knots_.pop_front();
    ++first_knot_;
  }
}

void RaceCourse::advance_to(double t_s) {
  while (static_cast<double>(next_step_ - 1) * kStepS < t_s) step();
}

CourseState RaceCourse::fix_at(double t_s) {
  const auto k = static_cast<std::int64_t>(std::floor(std::max(0.0, t_s) / kStepS + 1e-9));
  advance_to(static_cast<double>(k) * kStepS);
  const std::int64_t i = std::max<std::int64_t>(0, k - first_step_);
  return steps_[static_cast<std::size_t>(i)].state;
}

RaceCourse::Smooth RaceCourse::smooth_at(double t_s) const {
  if (knots_.empty()) return {};
  const double x = t_s / kKnotS;
  const auto j = static_cast<std::int64_t>(std::floor(x));
  const double u = x - static_cast<double>(j);
  const auto last = first_knot_ + static_cast<std::int64_t>(knots_.size()) - 1;
  const auto knot = [&](std::int64_t i) -> const Smooth& {
    return knots_[static_cast<std::size_t>(std::clamp(i, first_knot_, last) - first_knot_)];
  };
  // The uniform cubic B-spline's basis on [j, j + 1).
  const double u2 = u * u, u3 = u2 * u;
  const double b[4] = {(1.0 - u) * (1.0 - u) * (1.0 - u) / 6.0, (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0,
                       (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0, u3 / 6.0};
  Smooth s;
  for (int m = 0; m < 4; ++m) {
    const Smooth& p = knot(j - 1 + m);
    s.heading_rad += b[m] * p.heading_rad;
    s.speed_m_s += b[m] * p.speed_m_s;
    s.heel_rad += b[m] * p.heel_rad;
  }
  return s;
}

}  // namespace telltale::fusion::sim
