#pragma once
/// \file
/// PDR stage (phone pipeline): the heading over the last seconds, so that the steps a gap held
/// (StepClock) are laid along the heading each part of the gap had: a corner walked while the
/// detector was blind is a corner, not a diagonal.
///
/// Memory: fixed-size arrays, no heap.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>

namespace telltale::fusion {

class RecentHeadings {
 public:
  RecentHeadings();
  /// Per sample: the heading filter's heading as (cos, sin).
  void add(double t_s, const Eigen::Vector2d& unit);
  /// The walking frame changed at t_s: the headings before are in another frame.
  void new_frame(double t_s) { bins_from_t_s_ = t_s; }
  /// For a gap [t0, t1] walked in `parts` equal steps: the mean of the unit vectors of each
  /// part's heading relative to the whole gap's (x along, y clockwise); (1, 0) when the
  /// headings kept do not cover the gap.
  [[nodiscard]] Eigen::Vector2d gap_turn(double t0_s, double t1_s, int parts) const;

 private:
  /// 0.1 s bins (sums of unit vectors, since the walking frame last changed).
  static constexpr std::size_t kBins = 64;
  static constexpr double kBinS = 0.1;
  std::array<Eigen::Vector2d, kBins> bins_{};
  std::array<std::int64_t, kBins> bin_id_{};
  double bins_from_t_s_ = 0.0;
};

}  // namespace telltale::fusion
