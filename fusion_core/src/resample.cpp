#include "telltale/fusion/resample.hpp"

#include <algorithm>

namespace telltale::fusion {

std::vector<ResampleSpan> resample_spans(const std::vector<double>& t_in, double rate_hz) {
  std::vector<ResampleSpan> out;
  if (t_in.size() < 2 || !(rate_hz > 0.0)) {
    for (std::size_t i = 0; i < t_in.size(); ++i) out.push_back({t_in[i], i, i, 0.0, false});
    return out;
  }
  std::vector<double> dts;
  for (std::size_t i = 1; i < t_in.size(); ++i) dts.push_back(t_in[i] - t_in[i - 1]);
  const auto mid = dts.begin() + static_cast<std::ptrdiff_t>(dts.size() / 2);
  std::nth_element(dts.begin(), mid, dts.end());
  const double dt_in = *mid, period = 1.0 / rate_hz;
  const bool averaging = period > dt_in;
  std::size_t i = 0;  // averaging: the first input not yet used; interpolating: the left one
  for (long k = 0;; ++k) {
    const double t = t_in.front() + static_cast<double>(k) * period;
    if (t > t_in.back()) break;
    if (averaging) {
      while (i < t_in.size() && t_in[i] <= t - period) ++i;
      const std::size_t first = i;
      while (i < t_in.size() && t_in[i] <= t) ++i;
      if (i > first) out.push_back({t, first, i - 1, 0.0, false});
    } else {
      while (i + 2 < t_in.size() && t_in[i + 1] <= t) ++i;
      const double span = t_in[i + 1] - t_in[i];
      if (span > 3.0 * dt_in) continue;
      const double frac = span > 0.0 ? std::clamp((t - t_in[i]) / span, 0.0, 1.0) : 0.0;
      out.push_back({t, i, i + 1, frac, true});
    }
  }
  return out;
}

}  // namespace telltale::fusion
