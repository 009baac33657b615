#include "telltale/fusion/pdr/recent_headings.hpp"

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

RecentHeadings::RecentHeadings() { bin_id_.fill(std::numeric_limits<std::int64_t>::min()); }

void RecentHeadings::add(double t_s, const Eigen::Vector2d& unit) {
  const auto id = static_cast<std::int64_t>(std::floor(t_s / kBinS));
  const std::size_t slot = ring_slot(id, kBins);
  if (bin_id_[slot] != id) {
    bin_id_[slot] = id;
    bins_[slot].setZero();
  }
  bins_[slot] += unit;
}

Eigen::Vector2d RecentHeadings::gap_turn(double t0_s, double t1_s, int parts) const {
  const Eigen::Vector2d none(1.0, 0.0);
  if (parts < 2 || !(t1_s > t0_s) || t0_s < bins_from_t_s_ ||
      t1_s - t0_s > kBinS * static_cast<double>(kBins - 2))
    return none;
  // Each part's heading: the circular mean of the bins its interval covers.
  std::array<Eigen::Vector2d, kBins> part{};
  Eigen::Vector2d all = Eigen::Vector2d::Zero();
  const double span = (t1_s - t0_s) / parts;
  for (int j = 0; j < parts; ++j) {
    const double a = t0_s + j * span, b = a + span;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (auto id = static_cast<std::int64_t>(std::floor(a / kBinS));
         static_cast<double>(id) * kBinS < b; ++id) {
      const std::size_t slot = ring_slot(id, kBins);
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
