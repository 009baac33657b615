// Heel against speed per point of sailing (see sailing_stats.hpp).
#include "sailing_stats.hpp"

#include <cmath>
#include <limits>

#include "telltale/fusion/angles.hpp"

namespace telltale::shore {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool sailing(const SailingPoint& p) {
  return std::isfinite(p.sog_m_s) && std::isfinite(p.cog_deg) && p.sog_m_s >= kSailingMinSog_m_s;
}

}  // namespace

std::optional<double> estimate_wind_from_deg(const std::vector<SailingPoint>& pts) {
  // Time per degree of course, then the circular band sums.
  std::array<double, 360> course{};
  double total = 0.0;
  for (const auto& p : pts) {
    if (!sailing(p)) continue;
    const auto bin = static_cast<std::size_t>(std::fmod(std::fmod(p.cog_deg, 360.0) + 360.0, 360.0)) % 360;
    course[bin] += p.dt_s;
    total += p.dt_s;
  }
  if (total <= 0.0) return std::nullopt;
  double best_score = -1.0;
  std::size_t best = 0;
  for (std::size_t w = 0; w < 360; ++w) {
    // Both tacks must be there: a straight reach is not a beat.
    double left = 0.0, right = 0.0;
    for (std::size_t off = 30; off <= 55; ++off) {
      right += course[(w + off) % 360];
      left += course[(w - off + 360) % 360];
    }
    const double score = std::min(left, right) * 2.0;
    if (score > best_score) {
      best_score = score;
      best = w;
    }
  }
  if (best_score < 0.2 * total) return std::nullopt;
  // The band is 25 deg wide, so the best direction is only known to +-12 deg. The wind bisects
  // the tacking angle: refine it as the bisector of the two tacks' mean courses (twice: the
  // first bisector recentres the bands).
  double refined = static_cast<double>(best);
  for (int pass = 0; pass < 2; ++pass) {
    double sx[2] = {0, 0}, sy[2] = {0, 0};
    for (const auto& p : pts) {
      if (!sailing(p)) continue;
      const double off = fusion::diff_180_deg(p.cog_deg, refined);
      const double a = std::abs(off);
      if (a < 25.0 || a > 60.0) continue;
      const int side = off > 0 ? 1 : 0;
      sx[side] += p.dt_s * std::cos(p.cog_deg * M_PI / 180.0);
      sy[side] += p.dt_s * std::sin(p.cog_deg * M_PI / 180.0);
    }
    if ((sx[0] == 0 && sy[0] == 0) || (sx[1] == 0 && sy[1] == 0)) break;
    const double m0 = std::atan2(sy[0], sx[0]) * 180.0 / M_PI;
    const double m1 = std::atan2(sy[1], sx[1]) * 180.0 / M_PI;
    refined = std::fmod(m0 + fusion::diff_180_deg(m1, m0) / 2.0 + 360.0, 360.0);
  }
  // Upwind or downwind: upwind the boat heels away from the wind's side. Starboard tack (wind
  // over the starboard side, course left of the wind) heels to port (heel < 0).
  const auto agreement = [&](double w) {
    double a = 0.0;
    for (const auto& p : pts) {
      if (!sailing(p) || !std::isfinite(p.heel_deg)) continue;
      const double off =
          fusion::diff_180_deg(w, p.cog_deg);  // + : wind clockwise of the course = starboard
      if (std::abs(off) < 30.0 || std::abs(off) > 55.0) continue;
      a += (off > 0 ? -p.heel_deg : p.heel_deg) * p.dt_s;
    }
    return a;
  };
  const double w = refined, opposite = std::fmod(w + 180.0, 360.0);
  return agreement(w) >= agreement(opposite) ? w : opposite;
}

HeelSpeed heel_speed(const std::vector<SailingPoint>& pts, std::optional<double> wind_from_deg) {
  HeelSpeed out;
  out.wind_from_deg = wind_from_deg;
  if (!wind_from_deg) {
    out.wind_from_deg = estimate_wind_from_deg(pts);
    out.wind_estimated = out.wind_from_deg.has_value();
  }
  std::array<std::array<double, HeelSpeed::kEdges.size() - 1>, 4> sog_time{};
  HeelSpeed::Bands* groups[4] = {&out.upwind_port, &out.upwind_starboard, &out.downwind_port,
                                 &out.downwind_starboard};
  for (auto* g : groups)
    for (std::size_t i = 0; i < g->size(); ++i) {
      (*g)[i].from_deg = HeelSpeed::kEdges[i];
      (*g)[i].to_deg = HeelSpeed::kEdges[i + 1];
    }
  for (const auto& p : pts) {
    out.total_s += p.dt_s;
    if (!std::isfinite(p.sog_m_s)) {
      out.no_fix_s += p.dt_s;
      continue;
    }
    if (!sailing(p) || !std::isfinite(p.heel_deg)) {
      out.slow_s += p.dt_s;
      continue;
    }
    if (!out.wind_from_deg) {
      out.unsplit_s += p.dt_s;
      continue;
    }
    const double off = fusion::diff_180_deg(*out.wind_from_deg, p.cog_deg);
    const double a = std::abs(off);
    if (a > 70.0 && a < 110.0) {
      out.reaching_s += p.dt_s;
      continue;
    }
    const bool starboard = off > 0.0;  // the wind comes over the starboard side
    const int g = (a <= 70.0 ? 0 : 2) + (starboard ? 1 : 0);
    std::size_t band = 0;
    while (band + 2 < HeelSpeed::kEdges.size() && p.heel_deg >= HeelSpeed::kEdges[band + 1]) ++band;
    (*groups[g])[band].seconds += p.dt_s;
    sog_time[static_cast<std::size_t>(g)][band] += p.sog_m_s * p.dt_s;
  }
  for (std::size_t g = 0; g < 4; ++g)
    for (std::size_t i = 0; i < groups[g]->size(); ++i) {
      auto& b = (*groups[g])[i];
      b.mean_sog_m_s = b.seconds > 0.0 ? sog_time[g][i] / b.seconds : kNaN;
    }
  return out;
}

}  // namespace telltale::shore
