#pragma once
/// \file
/// A recording as a sensor at another rate would have given it: the one resampler of the
/// evaluation tools (`steps-eval --rate-hz`, `eval attitude --broad-rate-hz`). It says which
/// inputs make each output; callers apply that to every column they carry (rates, specific
/// force, field, truth).

#include <cstddef>
#include <type_traits>
#include <vector>

namespace telltale::fusion {

/// One output sample: its time and the inputs it is made of.
struct ResampleSpan {
  double t_s = 0.0;
  std::size_t first = 0,
              last = 0;  ///< averaged: inputs first..last; interpolated: last = first + 1
  double frac = 0.0;     ///< interpolated: the weight of `last` (0..1)
  bool interpolated = false;
};

/// Outputs on a grid from the first input time at `rate_hz`. Below the inputs' rate (their
/// median interval shorter than the period), each output is the mean of the inputs in
/// (t - period, t]: the interval before it, as a sensor averaging to its output rate delivers
/// it and as the filters integrate a rate. Above it, the inputs around t interpolated linearly
/// (no new content: what changes shows what depends on the rate itself). Where an averaging
/// interval holds no input, or the inputs around t are more than three median intervals apart,
/// there is no output: a gap stays a gap. `t_in` in time order; fewer than two inputs or a rate
/// that is not positive: one span per input, as it is.
[[nodiscard]] std::vector<ResampleSpan> resample_spans(const std::vector<double>& t_in,
                                                       double rate_hz);

/// One column's value at a span: `get(i)` is the i-th input's (a double or an Eigen vector).
template <class Get>
[[nodiscard]] auto resampled(const ResampleSpan& s, Get&& get) {
  using T = std::decay_t<decltype(get(s.first))>;
  if (s.interpolated) return T(get(s.first) + s.frac * (get(s.last) - get(s.first)));
  T sum = get(s.first);
  for (std::size_t i = s.first + 1; i <= s.last; ++i) sum += get(i);
  return T(sum / static_cast<double>(s.last - s.first + 1));
}

}  // namespace telltale::fusion
