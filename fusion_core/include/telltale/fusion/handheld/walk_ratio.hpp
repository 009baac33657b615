#pragma once
/// \file
/// Hand-held phone PDR stage (HandheldPdr, handheld_pdr.hpp): step length from height and
/// cadence by the walk ratio. No state: a step's length depends only on the walker's height and
/// the cadence at that step. Header only: the law is one inline line.

namespace telltale::fusion {

/// Step length from height and cadence, by the walk ratio. People choose, at every walking
/// speed from a stroll to a brisk walk, nearly the same ratio of step length to cadence (the
/// "walk ratio": the combination of the two that costs least energy per metre); a faster walk
/// lengthens the step and quickens the cadence in proportion. The ratio scales with body size.
/// Anchored on the population norm at the preferred speed, a step of 0.415 x height at
/// 112 steps/min: ratio / height = 0.415 / 112 = 0.0037 per (step/min), so
///   L = 0.0037 x height x 60 f = 0.222 x height x f     (L, height in m; f in steps/s).
/// At 1.75 m: 0.65 m at 100 steps/min, 0.58 m at 90. This replaces seed 003's linear
/// L = a h + b f + c for the hand-held phone: its coefficients were fitted to our own gait
/// simulator, whose walkers take a 0.67-0.72 m step at 95-100 steps/min, longer than people do.
/// Below about 98 steps/min the ratio is known to grow (slow walkers shorten the step less than
/// the cadence); that is not modelled, so a slow walker's distance comes out a little short.
struct WalkRatioParams {
  double ratio_per_height_min = 0.0037;  ///< walk ratio / height, m per (step/min) per m
};
[[nodiscard]] inline double walk_ratio_step_length_m(double height_m, double step_hz,
                                                     const WalkRatioParams& p = {}) {
  return p.ratio_per_height_min * height_m * 60.0 * step_hz;
}

}  // namespace telltale::fusion
