#pragma once
/// \file
/// The median of a handful of values without the heap (step intervals, step peaks): sorted into
/// a fixed copy by insertion.

#include <array>
#include <cstddef>
#include <span>

namespace telltale::fusion {

/// The median of `values` (at most N of them are read; the mean of the middle two for an even
/// count); 0 for none.
template <std::size_t N>
[[nodiscard]] double small_median(std::span<const double> values) {
  std::array<double, N> sorted{};
  std::size_t n = 0;
  for (std::size_t i = 0; i < values.size() && n < N; ++i) {
    const double v = values[i];
    std::size_t j = n++;
    for (; j > 0 && sorted[j - 1] > v; --j) sorted[j] = sorted[j - 1];
    sorted[j] = v;
  }
  if (n == 0) return 0.0;
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

}  // namespace telltale::fusion
