// Manoeuvres found and measured (see manoeuvres.hpp for every definition).
#include "telltale/fusion/manoeuvres.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDt = 0.1;  // grid step, s

// Differences go through diff_180_deg, right for any a and b: b is often the unwrapped course,
// which a 720 or a day of rounding marks one way takes past +-540, where fmod(a - b + 540) went
// negative and the course jumped by 360 (a later turn then measured, or taken for a penalty, by
// where the data began).

/// Circular median: the sample minimising the summed absolute circular distance.
double circular_median(const std::vector<double>& a) {
  double best = a.front(), best_cost = 1e300;
  for (double c : a) {
    double cost = 0.0;
    for (double x : a) cost += std::abs(diff_180_deg(x, c));
    if (cost < best_cost) best_cost = cost, best = c;
  }
  return best;
}

/// The samples on a 10 Hz grid, with prefix sums for window means.
struct Grid {
  double t_start = 0.0;
  std::size_t n = 0;
  std::vector<double> course;   // unwrapped, deg (NaN: gap)
  std::vector<double> sog;      // NaN: gap
  std::vector<double> ve, vn;   // velocity east/north from SOG and COG, m/s
  std::vector<double> heel, pitch;
  // Prefix sums (size n+1).
  std::vector<double> pc, ps, pn, psog, pnsog, pve, pvn, pnv, pheel, pnheel, pu;
  bool has_heel = false;

  [[nodiscard]] double t(std::size_t k) const { return t_start + static_cast<double>(k) * kDt; }
  [[nodiscard]] long idx(double t_s) const { return std::lround((t_s - t_start) / kDt); }
  [[nodiscard]] std::pair<std::size_t, std::size_t> clamp(long a, long b) const {
    // Both ends inside [0, n]: a window that starts after the last tick (a manoeuvre near the
    // end of the data) is empty, never read past the prefix sums (ASan caught it).
    const long last = static_cast<long>(n);
    a = std::clamp(a, 0L, last);
    b = std::clamp(b, a, last);
    return {static_cast<std::size_t>(a), static_cast<std::size_t>(b)};
  }
  /// Circular mean course over ticks [a, b) (deg in [0, 360)) and its mean resultant length;
  /// NaN when under half the window has data.
  [[nodiscard]] double mean_course(long a0, long b0, double* r = nullptr) const {
    auto [a, b] = clamp(a0, b0);
    const double cnt = pn[b] - pn[a];
    if (b0 <= a0 || cnt < 0.5 * static_cast<double>(b0 - a0)) return kNaN;
    const double c = pc[b] - pc[a], s = ps[b] - ps[a];
    if (r) *r = std::hypot(c, s) / cnt;
    return wrap_360_deg(std::atan2(s, c) / kDeg);
  }
  /// Mean of the unwrapped course over [a, b) (only within a window without a full turn).
  [[nodiscard]] double mean_unwrapped(long a0, long b0) const {
    auto [a, b] = clamp(a0, b0);
    const double cnt = pn[b] - pn[a];
    if (cnt < 0.5 * static_cast<double>(b0 - a0) || cnt <= 0) return kNaN;
    return (pu[b] - pu[a]) / cnt;
  }
  [[nodiscard]] double mean_sog(long a0, long b0) const {
    auto [a, b] = clamp(a0, b0);
    const double cnt = pnsog[b] - pnsog[a];
    if (cnt < 0.5 * static_cast<double>(b0 - a0) || cnt <= 0) return kNaN;
    return (psog[b] - psog[a]) / cnt;
  }
  /// Mean velocity (east, north) over [a, b).
  [[nodiscard]] std::pair<double, double> mean_vel(long a0, long b0) const {
    auto [a, b] = clamp(a0, b0);
    const double cnt = pnv[b] - pnv[a];
    if (cnt < 0.5 * static_cast<double>(b0 - a0) || cnt <= 0) return {kNaN, kNaN};
    return {(pve[b] - pve[a]) / cnt, (pvn[b] - pvn[a]) / cnt};
  }
  /// Distance made along the unit (ue, un) over [a, b): velocity integrated (gaps: the mean).
  [[nodiscard]] double made_along(long a0, long b0, double ue, double un) const {
    auto [me, mn] = mean_vel(a0, b0);
    return (me * ue + mn * un) * static_cast<double>(b0 - a0) * kDt;
  }
  [[nodiscard]] double mean_heel(long a0, long b0) const {
    auto [a, b] = clamp(a0, b0);
    const double cnt = pnheel[b] - pnheel[a];
    if (cnt < 0.5 * static_cast<double>(b0 - a0) || cnt <= 0) return kNaN;
    return (pheel[b] - pheel[a]) / cnt;
  }
  /// Course rate at k, deg/s (1 s central difference); NaN in gaps.
  [[nodiscard]] double rate(std::size_t k) const {
    if (k < 5 || k + 5 >= n) return kNaN;
    return (course[k + 5] - course[k - 5]) / 1.0;
  }
};

Grid make_grid(std::span<const CourseSample> in, std::span<const HeelSample> heel) {
  Grid g;
  if (in.empty()) return g;
  g.t_start = in.front().t_s;
  g.n = static_cast<std::size_t>(std::floor((in.back().t_s - g.t_start) / kDt)) + 1;
  g.course.assign(g.n, kNaN);
  g.sog.assign(g.n, kNaN);
  g.ve.assign(g.n, kNaN);
  g.vn.assign(g.n, kNaN);
  g.heel.assign(g.n, kNaN);
  g.pitch.assign(g.n, kNaN);
  std::size_t j = 0;
  double prev_course = kNaN;
  for (std::size_t k = 0; k < g.n; ++k) {
    const double t = g.t(k) + 1e-9;
    while (j + 1 < in.size() && in[j + 1].t_s <= t) ++j;
    const CourseSample& s = in[j];
    if (s.t_s > t || t - s.t_s > 1.0) continue;
    const double c = std::isfinite(s.heading_deg) ? s.heading_deg : s.cog_deg;
    if (std::isfinite(c) && std::isfinite(s.sog_m_s)) {
      const double u =
          std::isfinite(prev_course) ? prev_course + diff_180_deg(c, prev_course) : wrap_360_deg(c);
      g.course[k] = u;
      prev_course = u;
    }
    g.sog[k] = s.sog_m_s;
    if (std::isfinite(s.cog_deg) && std::isfinite(s.sog_m_s)) {
      g.ve[k] = s.sog_m_s * std::sin(s.cog_deg * kDeg);
      g.vn[k] = s.sog_m_s * std::cos(s.cog_deg * kDeg);
    } else if (std::isfinite(s.sog_m_s) && s.sog_m_s < 0.3) {
      g.ve[k] = g.vn[k] = 0.0;  // COG meaningless when nearly still
    }
  }
  if (!heel.empty()) {
    std::size_t h = 0;
    for (std::size_t k = 0; k < g.n; ++k) {
      const double t = g.t(k) + 1e-9;
      while (h + 1 < heel.size() && heel[h + 1].t_s <= t) ++h;
      if (heel[h].t_s > t || t - heel[h].t_s > 0.5) continue;
      g.heel[k] = heel[h].heel_deg;
      g.pitch[k] = heel[h].pitch_deg;
      g.has_heel = true;
    }
  }
  const auto prefix = [&](std::vector<double>& p, auto f) {
    p.assign(g.n + 1, 0.0);
    for (std::size_t k = 0; k < g.n; ++k) p[k + 1] = p[k] + f(k);
  };
  const auto ok = [](double v) { return std::isfinite(v); };
  prefix(g.pc, [&](std::size_t k) { return ok(g.course[k]) ? std::cos(g.course[k] * kDeg) : 0.0; });
  prefix(g.ps, [&](std::size_t k) { return ok(g.course[k]) ? std::sin(g.course[k] * kDeg) : 0.0; });
  prefix(g.pn, [&](std::size_t k) { return ok(g.course[k]) ? 1.0 : 0.0; });
  prefix(g.pu, [&](std::size_t k) { return ok(g.course[k]) ? g.course[k] : 0.0; });
  prefix(g.psog, [&](std::size_t k) { return ok(g.sog[k]) ? g.sog[k] : 0.0; });
  prefix(g.pnsog, [&](std::size_t k) { return ok(g.sog[k]) ? 1.0 : 0.0; });
  prefix(g.pve, [&](std::size_t k) { return ok(g.ve[k]) ? g.ve[k] : 0.0; });
  prefix(g.pvn, [&](std::size_t k) { return ok(g.vn[k]) ? g.vn[k] : 0.0; });
  prefix(g.pnv, [&](std::size_t k) { return ok(g.ve[k]) ? 1.0 : 0.0; });
  prefix(g.pheel, [&](std::size_t k) { return ok(g.heel[k]) ? g.heel[k] : 0.0; });
  prefix(g.pnheel, [&](std::size_t k) { return ok(g.heel[k]) ? 1.0 : 0.0; });
  return g;
}

/// A turn before classification.
struct Turn {
  long peak = 0;            // tick of the largest course rate
  long a = 0, b = 0;        // the ticks turning faster than 2 deg/s, first and last
  long ks = 0, ke = 0;      // [a, b] padded by 0.5 s, from steady course to steady course
  double total = 0.0;       // unwrapped turning over it, deg (signed)
  double before = 0.0, after = 0.0;  // mean unwrapped course before / after the turn
  double side_sog = kNaN, side_heel_abs = kNaN;  // how it sailed there (WindTurn)
  double t0_k = 0.0;        // fractional tick
  bool penalty = false;
};

/// The unwrapped course at k, or the nearest known one towards `toward` (a tick inside the
/// turn): the ends of a turn padded into a gap still measure it.
double course_near(const Grid& g, long k, long toward) {
  const long step = toward >= k ? 1 : -1;
  for (; k != toward + step; k += step) {
    const double u = g.course[static_cast<std::size_t>(k)];
    if (std::isfinite(u)) return u;
  }
  return kNaN;
}

/// The turning done over [ks, ke]: the mean course over the 0.5 s after ke minus the 0.5 s
/// before ks (single fixes there would carry their COG noise into it: 5 deg of noise would make
/// every fourth 1 s wobble a 15 deg "turn"); the single fixes where the data has no 0.5 s.
double turn_total(const Grid& g, const Turn& t) {
  double u0 = g.mean_unwrapped(t.ks - 5, t.ks), u1 = g.mean_unwrapped(t.ke + 1, t.ke + 6);
  if (!std::isfinite(u0)) u0 = course_near(g, t.ks, t.peak);
  if (!std::isfinite(u1)) u1 = course_near(g, t.ke, t.peak);
  return std::isfinite(u0) && std::isfinite(u1) ? u1 - u0 : 0.0;
}

/// Every continuous turn of the data: a run of ticks whose course rate (1 s central difference)
/// has one sign and exceeds 2 deg/s, dips of 0.3 s bridged (a noisy fix), ended by turning the
/// other way; longer pauses are judged by the caller (a wobbly tack, or a tack then a mark).
/// 2 deg/s is ten times what following a wind shift takes (5 deg over a few minutes) and well
/// under any helm's turn (a tack: 10-30 deg/s), so the runs are the helm's turns. The turn's
/// ends are padded by 0.5 s, the central difference's half width, so its total is measured from
/// steady course to steady course. Turns under `min_total_deg` (course corrections, COG noise in
/// waves) are dropped: they neither make a manoeuvre nor split a neighbouring one.
std::vector<Turn> continuous_turns(const Grid& g, double min_total_deg) {
  std::vector<Turn> out;
  const long n = static_cast<long>(g.n);
  const auto rate = [&](long k) { return g.rate(static_cast<std::size_t>(k)); };
  long k = 0;
  while (k < n) {
    const double r = rate(k);
    if (!std::isfinite(r) || std::abs(r) <= 2.0) {
      ++k;
      continue;
    }
    const double s = r > 0 ? 1.0 : -1.0;
    long b = k, peak = k;
    for (long j = k + 1, gap = 0; j < n; ++j) {
      const double rj = rate(j);
      if (std::isfinite(rj) && s * rj > 2.0) {
        b = j, gap = 0;
        if (std::abs(rj) > std::abs(rate(peak))) peak = j;
      } else if ((std::isfinite(rj) && -s * rj > 2.0) || ++gap > 3) {
        break;
      }
    }
    Turn t;
    t.peak = peak;
    t.a = k;
    t.b = b;
    t.ks = std::max(0L, k - 5);
    t.ke = std::min(n - 1, b + 5);
    t.total = turn_total(g, t);
    if (std::abs(t.total) >= min_total_deg) out.push_back(t);
    k = b + 1;
  }
  return out;
}

/// No neighbouring turn on that side (side_means).
constexpr long kNoPrev = std::numeric_limits<long>::min() / 4;
constexpr long kNoNext = std::numeric_limits<long>::max() / 4;

/// The mean courses before and after turn m over up to `span` ticks each, cut where the
/// neighbouring turns are turning (`prev_b`, `next_a`: their last and first turning ticks;
/// kNoPrev / kNoNext without one; their padding may overlap m's when 1-2 s apart). Uncut, a side
/// needs half its span of data: a turn the data ends 1 s after is not measured yet. Anchored on the
/// unwrapped turn: `before` on the course where the turn starts, `after` on the same unwrapping
/// as the turn measured through it (a 720 stays 720). false when a side has too little data.
bool side_means(const Grid& g, Turn& m, long span, long prev_b, long next_a) {
  // Each side from the padded end outwards; where a neighbour turns within the padding (turns
  // 1-2 s apart), the unpadded gap between the two. Never into the turn itself nor past the
  // data: a turn still going on where the data ends has no course after yet.
  long from = std::max(m.ks - span, prev_b + 1), b0 = m.ks;
  if (from >= b0 && prev_b != kNoPrev) from = prev_b + 1, b0 = m.a;
  long a0 = m.ke + 1, to = std::min(m.ke + 1 + span, next_a);
  if (to <= a0 && next_a != kNoNext) a0 = m.b + 1, to = next_a;
  m.before = g.mean_unwrapped(from, b0);
  m.after = g.mean_unwrapped(a0, to);
  m.side_sog = 0.5 * (g.mean_sog(from, b0) + g.mean_sog(a0, to));
  m.side_heel_abs = 0.5 * (std::abs(g.mean_heel(from, b0)) + std::abs(g.mean_heel(a0, to)));
  if (!std::isfinite(m.before) || !std::isfinite(m.after)) return false;
  const double u0 = course_near(g, m.ks, m.peak);
  if (std::isfinite(u0)) m.before += 360.0 * std::round((u0 - m.before) / 360.0);
  const double raw = m.after - m.before;
  m.after = m.before + raw - 360.0 * std::round((raw - m.total) / 360.0);
  return true;
}

/// Kind from the wind: where the unwrapped path from the course before crosses the wind.
ManoeuvreKind classify(double before_deg, double total_deg, double wind_from, bool penalty) {
  if (penalty) return ManoeuvreKind::kPenalty;
  const double rb = diff_180_deg(before_deg, wind_from);  // 0: head to wind
  const double lo = std::min(rb, rb + total_deg), hi = std::max(rb, rb + total_deg);
  const auto crosses = [&](double v) {
    for (double x = v - 720.0; x <= v + 720.0; x += 360.0)
      if (x > lo && x < hi) return true;
    return false;
  };
  const bool eye = crosses(0.0), down = crosses(180.0);
  if (eye && !down) return ManoeuvreKind::kTack;
  if (down && !eye) return ManoeuvreKind::kGybe;
  if (eye && down) return ManoeuvreKind::kOther;
  const double ra = diff_180_deg(before_deg + total_deg, wind_from);
  return std::abs(ra) > std::abs(rb) ? ManoeuvreKind::kBearAway : ManoeuvreKind::kRoundUp;
}

/// What the wind estimate needs of a measured turn: the unwrapped mean course before it, its
/// signed turn (after - before), whether it is a penalty turn, its bisector, and how the boat
/// sailed on the steady courses either side: mean SOG and mean |heel| (NaN when unknown).
struct WindTurn {
  double before = 0.0, total = 0.0;
  bool penalty = false;
  double bisector = 0.0;
  double sog = kNaN, heel_abs = kNaN;
};

/// Which end of the wind axis is upwind, as evidence for `wind`: > 0 when the turns it calls
/// tacks sailed as a boat sails upwind, against the ones it calls gybes. The physics, strongest
/// first:
///  - heel: the apparent wind is the true wind plus the boat's own speed when beating and minus
///    it when running, so every sailing boat heels more close-hauled than running (a dinghy:
///    10-20 deg against 0-6, whichever side it runs on);
///  - speed: close-hauled is a boat's slowest point of sail; every polar runs faster than it
///    beats at the wind speeds a race sails in.
/// 0 when it calls no turn a tack or none a gybe (nothing to compare).
double upwind_evidence(const std::vector<WindTurn>& turns, double wind) {
  double heel[2] = {0, 0}, sog[2] = {0, 0};
  int nh[2] = {0, 0}, ns[2] = {0, 0};
  for (const auto& m : turns) {
    const auto k = classify(wrap_360_deg(m.before), m.total, wind, m.penalty);
    if (k != ManoeuvreKind::kTack && k != ManoeuvreKind::kGybe) continue;
    const int i = k == ManoeuvreKind::kTack ? 0 : 1;
    if (std::isfinite(m.heel_abs)) heel[i] += m.heel_abs, ++nh[i];
    if (std::isfinite(m.sog)) sog[i] += m.sog, ++ns[i];
  }
  if (nh[0] && nh[1]) {
    const double d = heel[0] / nh[0] - heel[1] / nh[1];
    if (std::abs(d) >= 1.0) return d;  // a degree of heel apart: the heel says it
  }
  if (ns[0] && ns[1]) return sog[1] / ns[1] - sog[0] / ns[0];
  return 0.0;
}

/// The wind estimated from the turns (see the file comment): the axis from the doubled bisectors
/// of the turns of 50-140 deg, its upwind end from how the boat sailed (upwind_evidence; with
/// tacks or gybes only, from tacks turning more than 72 deg), then twice the median of the
/// tacks' bisectors and the gybes' inverted.
std::optional<double> wind_from_turns(const std::vector<WindTurn>& turns) {
  std::vector<double> doubled;
  for (const auto& m : turns) {
    const double t = std::abs(m.total);
    if (!m.penalty && t >= 50.0 && t <= 140.0) doubled.push_back(wrap_360_deg(2.0 * m.bisector));
  }
  if (doubled.empty()) return std::nullopt;
  std::optional<double> wind;
  const double axis = circular_median(doubled) / 2.0;
  double evidence = upwind_evidence(turns, axis);
  if (evidence == 0.0) {
    // Tacks only or gybes only: the end where the turns it calls tacks exceed 72 deg.
    for (const auto& m : turns) {
      const auto k = classify(wrap_360_deg(m.before), m.total, axis, m.penalty);
      const double t = std::abs(m.total);
      if (k == ManoeuvreKind::kTack) evidence += t - 72.0;
      if (k == ManoeuvreKind::kGybe) evidence -= t - 72.0;
    }
  }
  wind = evidence >= 0.0 ? axis : wrap_360_deg(axis + 180.0);
  // The median of the tacks' bisectors and the gybes' inverted, twice.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<double> b;
    for (const auto& m : turns) {
      const auto k = classify(wrap_360_deg(m.before), m.total, *wind, m.penalty);
      if (k == ManoeuvreKind::kTack) b.push_back(m.bisector);
      if (k == ManoeuvreKind::kGybe) b.push_back(wrap_360_deg(m.bisector + 180.0));
    }
    if (b.empty()) break;
    wind = circular_median(b);
  }
  return wind;
}

}  // namespace

const char* to_string(ManoeuvreKind k) {
  switch (k) {
    case ManoeuvreKind::kTack: return "tack";
    case ManoeuvreKind::kGybe: return "gybe";
    case ManoeuvreKind::kBearAway: return "bear_away";
    case ManoeuvreKind::kRoundUp: return "round_up";
    case ManoeuvreKind::kPenalty: return "penalty";
    case ManoeuvreKind::kOther: return "other";
  }
  return "other";
}

ManoeuvreReport analyse_manoeuvres(std::span<const CourseSample> course,
                                   std::span<const HeelSample> heel,
                                   const ManoeuvreOptions& o) {
  ManoeuvreReport rep;
  if (course.size() < 2) return rep;
  const Grid g = make_grid(course, heel);
  const long n = static_cast<long>(g.n);
  const long w = std::lround(o.window_s / kDt);

  // 1. The helm's turns (continuous_turns). Two turns of one sign with under 3 s between their
  // turning ticks (about 4 s of steady course: the rate's 1 s smear) are one manoeuvre (a tack with a pause in it),
  // unless each is a manoeuvre on its own: a tack on the layline 2 s before the mark and the
  // rounding are two, measured apart. Turns of opposite signs are never one.
  const double split_deg = 0.5 * o.min_turn_deg;
  const std::vector<Turn> segs = continuous_turns(g, 0.25 * o.min_turn_deg);
  // A turn is a manoeuvre when the mean course over the `window_s` before it starts and after it
  // ends (cut at the neighbouring turns) differs by >= min_turn_deg, at a mean SOG >= min_sog
  // before it. This is the "10 s before and after t" with the turn itself taken out of
  // the windows: a 60 deg gybe taking 3 s reads 60, not the 52-56 the windows about one tick see.
  const auto is_manoeuvre = [&](Turn t, long prev_b, long next_a) {
    if (!side_means(g, t, w, prev_b, next_a)) return false;
    const double sog = g.mean_sog(std::max(t.ks - w, prev_b + 1), std::max(prev_b + 2, t.ks));
    return std::abs(t.after - t.before) >= o.min_turn_deg && std::isfinite(sog) &&
           sog >= o.min_sog_m_s;
  };
  // The neighbours that cut a turn's windows: turns of at least half the threshold. Smaller ones
  // are course keeping, averaged into the course either side (a 15 deg wobble just before a tack
  // would otherwise leave it no course before).
  const auto last_cut = [&](const std::vector<Turn>& list, std::size_t from) {
    for (std::size_t j = from + 1; j-- > 0;)
      if (std::abs(list[j].total) >= split_deg) return list[j].b;
    return kNoPrev;
  };
  const auto next_cut = [&](const std::vector<Turn>& list, std::size_t from) {
    for (std::size_t j = from; j < list.size(); ++j)
      if (std::abs(list[j].total) >= split_deg) return list[j].a;
    return kNoNext;
  };
  std::vector<Turn> merged;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    Turn c = segs[i];
    if (!merged.empty()) {
      Turn& p = merged.back();
      const bool same_sign = (p.total > 0) == (c.total > 0);
      if (same_sign && c.a - p.b < 30) {
        const long pp = merged.size() > 1 ? last_cut(merged, merged.size() - 2) : kNoPrev;
        const long nn = next_cut(segs, i + 1);
        const bool apart = std::abs(p.total) >= split_deg && std::abs(c.total) >= split_deg &&
                           is_manoeuvre(p, pp, c.a) && is_manoeuvre(c, p.b, nn);
        if (!apart) {
          const double rp = std::abs(g.rate(static_cast<std::size_t>(p.peak)));
          if (std::abs(g.rate(static_cast<std::size_t>(c.peak))) > rp) p.peak = c.peak;
          p.ke = c.ke;
          p.b = c.b;
          p.total = turn_total(g, p);
          continue;
        }
      }
    }
    merged.push_back(c);
  }
  std::vector<Turn> turns;
  for (std::size_t i = 0; i < merged.size(); ++i) {
    const long pk = i > 0 ? last_cut(merged, i - 1) : kNoPrev;
    const long nk = next_cut(merged, i + 1);
    if (is_manoeuvre(merged[i], pk, nk)) turns.push_back(merged[i]);
  }

  // 2. t0 and the means around it.
  std::vector<Turn> valid;
  for (std::size_t i = 0; i < turns.size(); ++i) {
    Turn& m = turns[i];
    m.penalty = std::abs(m.total) >= o.penalty_deg;
    // The steady courses either side: 15 s (the turn angle's 20-5 s about t0 when the turn
    // takes ~10 s), cut short by the neighbouring manoeuvres' turns.
    const long prev_b = i > 0 ? turns[i - 1].b : kNoPrev;
    const long next_a = i + 1 < turns.size() ? turns[i + 1].a : kNoNext;
    if (!side_means(g, m, 150, prev_b, next_a)) continue;
    const double half = m.before + 0.5 * (m.after - m.before);
    const double s = m.after >= m.before ? 1.0 : -1.0;
    m.t0_k = static_cast<double>(m.peak);
    for (long k = std::max(1L, m.ks - 50); k <= std::min(n - 1, m.ke + 50); ++k) {
      const double u1 = g.course[static_cast<std::size_t>(k)], u0k = g.course[static_cast<std::size_t>(k - 1)];
      if (!std::isfinite(u1) || !std::isfinite(u0k)) continue;
      if (s * (u0k - half) < 0 && s * (u1 - half) >= 0) {
        m.t0_k = static_cast<double>(k - 1) + (half - u0k) / (u1 - u0k);
        break;
      }
    }
    valid.push_back(m);
  }

  // 3. The wind: given, or estimated from the turns.
  const auto bisector = [](const Turn& m) { return wrap_360_deg(0.5 * (m.before + m.after)); };
  std::optional<double> wind = o.wind_from_deg;
  if (wind) {
    rep.wind_given = true;
  } else {
    std::vector<WindTurn> wt;
    for (const auto& m : valid)
      wt.push_back({m.before, m.after - m.before, m.penalty, bisector(m), m.side_sog, m.side_heel_abs});
    wind = wind_from_turns(wt);
  }
  rep.wind_from_deg = wind;

  // 4. Classify and measure.
  std::vector<double> running;
  for (const auto& m : valid) {
    Manoeuvre r;
    const double total = m.after - m.before;
    // The wind where this manoeuvre was: an instrument's reading of its time, else the session's.
    std::optional<double> here = wind;
    if (o.wind_at) {
      if (const auto measured = o.wind_at(g.t_start + m.t0_k * kDt)) here = *measured;
    }
    r.kind = here ? classify(wrap_360_deg(m.before), total, *here, m.penalty)
                  : (m.penalty ? ManoeuvreKind::kPenalty : ManoeuvreKind::kOther);
    const long k0 = std::lround(m.t0_k);
    r.t0_s = g.t_start + m.t0_k * kDt;
    r.turn_deg = std::abs(total);
    r.turn_dir = total >= 0 ? 1 : -1;
    r.course_before_deg = wrap_360_deg(m.before);
    r.course_after_deg = wrap_360_deg(m.after);
    r.bisector_deg = m.penalty ? wrap_360_deg(m.before) : bisector(m);
    const auto at = [&](double s) { return k0 + std::lround(s / kDt); };
    r.entry_sog_m_s = g.mean_sog(at(-20), at(-10));
    r.exit_sog_m_s = g.mean_sog(at(15), at(25));
    r.min_sog_m_s = kNaN;
    long k_min = k0;
    for (long k = std::max(0L, at(-5)); k < std::min(n, at(15)); ++k) {
      const double v = g.sog[static_cast<std::size_t>(k)];
      if (std::isfinite(v) && !(v >= r.min_sog_m_s)) r.min_sog_m_s = v, k_min = k;
    }
    r.speed_loss_m_s = r.entry_sog_m_s - r.min_sog_m_s;
    r.recovery_s = kNaN;
    for (long k = k_min; k < std::min(n, at(60)); ++k) {
      const double v = g.sog[static_cast<std::size_t>(k)];
      if (std::isfinite(v) && v >= 0.9 * r.entry_sog_m_s) {
        r.recovery_s = static_cast<double>(k) * kDt + g.t_start - r.t0_s;
        break;
      }
    }
    // 10 % to 90 % of the turn.
    double t10 = kNaN, t90 = kNaN;
    for (long k = std::max(0L, m.ks - 50); k <= std::min(n - 1, m.ke + 50); ++k) {
      const double u = g.course[static_cast<std::size_t>(k)];
      if (!std::isfinite(u) || total == 0.0) continue;
      const double f = (u - m.before) / total;
      if (f <= 0.1 && !std::isfinite(t90)) t10 = g.t(static_cast<std::size_t>(k));
      if (f >= 0.9 && !std::isfinite(t90)) t90 = g.t(static_cast<std::size_t>(k));
    }
    r.turn_duration_s = t90 - t10;
    r.max_turn_rate_deg_s = kNaN;
    for (long k = std::max(0L, at(-10)); k < std::min(n, at(10)); ++k) {
      const double rr = std::abs(g.rate(static_cast<std::size_t>(k)));
      if (std::isfinite(rr) && !(rr <= r.max_turn_rate_deg_s)) r.max_turn_rate_deg_s = rr;
    }
    r.mean_turn_rate_deg_s = 0.8 * r.turn_deg / r.turn_duration_s;
    // Distance lost along the mean course, and against the wind.
    const double ue = std::sin(r.bisector_deg * kDeg), un = std::cos(r.bisector_deg * kDeg);
    const auto [ee, en] = g.mean_vel(at(-20), at(-10));
    r.distance_lost_m = (ee * ue + en * un) * 30.0 - g.made_along(at(-10), at(20), ue, un);
    r.vmg_lost_m = kNaN;
    if (here) {
      const bool up = std::abs(diff_180_deg(r.course_before_deg, *here)) < 90.0;
      const double wd = up ? *here : wrap_360_deg(*here + 180.0);
      const double we = std::sin(wd * kDeg), wn = std::cos(wd * kDeg);
      r.vmg_lost_m = (ee * we + en * wn) * 30.0 - g.made_along(at(-10), at(20), we, wn);
    }
    // Heel and pitch.
    r.heel_peak_deg = r.heel_peak_windward_deg = r.heel_peak_leeward_deg = kNaN;
    r.heel_zero_s = r.exit_heel_deg = r.pitch_min_deg = r.pitch_max_deg = r.pitch_mean_deg = kNaN;
    if (g.has_heel) {
      const double hb = g.mean_heel(at(-20), at(-5)), ha = g.mean_heel(at(5), at(20));
      const double side = ha >= 0 ? 1.0 : -1.0;  // the exit tack's leeward side
      double best_zero = 1e9;
      for (long k = std::max(1L, at(-10)); k < std::min(n, at(10)); ++k) {
        const double h = g.heel[static_cast<std::size_t>(k)], hp = g.heel[static_cast<std::size_t>(k - 1)];
        if (!std::isfinite(h)) continue;
        if (!(std::abs(h) <= std::abs(r.heel_peak_deg))) r.heel_peak_deg = h;
        if (!(h * side <= r.heel_peak_leeward_deg)) r.heel_peak_leeward_deg = h * side;
        if (!(-h * side <= r.heel_peak_windward_deg)) r.heel_peak_windward_deg = -h * side;
        if (std::isfinite(hp) && (hp < 0) != (h < 0)) {
          const double tz = g.t(static_cast<std::size_t>(k)) - r.t0_s;
          if (std::abs(tz) < std::abs(best_zero)) best_zero = tz;
        }
      }
      if (best_zero < 1e8) r.heel_zero_s = best_zero;
      r.exit_heel_deg = g.mean_heel(at(15), at(25));
      double ps = 0.0, pc = 0.0;
      for (long k = std::max(0L, at(-5)); k < std::min(n, at(10)); ++k) {
        const double p = g.pitch[static_cast<std::size_t>(k)];
        if (!std::isfinite(p)) continue;
        if (!(p >= r.pitch_min_deg)) r.pitch_min_deg = p;
        if (!(p <= r.pitch_max_deg)) r.pitch_max_deg = p;
        ps += p, pc += 1.0;
      }
      if (pc > 0) r.pitch_mean_deg = ps / pc;
      if ((r.kind == ManoeuvreKind::kTack || r.kind == ManoeuvreKind::kGybe) &&
          std::isfinite(hb) && std::isfinite(ha))
        r.heel_flip_agrees = (hb < 0) != (ha < 0) && std::abs(hb) > 1.0 && std::abs(ha) > 1.0;
    }
    // Unsteady entry.
    double res = 0.0;
    const double mc = g.mean_course(at(-20), at(-5), &res);
    r.entry_course_sd_deg = std::isfinite(mc) ? std::sqrt(-2.0 * std::log(std::max(res, 1e-12))) / kDeg : kNaN;
    double vmin = 1e9, vmax = -1e9;
    for (long k = std::max(0L, at(-20)); k < std::min(n, at(-10)); ++k) {
      const double v = g.sog[static_cast<std::size_t>(k)];
      if (std::isfinite(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    r.unsteady_entry = r.entry_course_sd_deg > 8.0 ||
                       (vmax >= vmin && (vmax - vmin) > 0.2 * r.entry_sog_m_s);
    // The wind estimate as it stood after each tack or gybe.
    if (!rep.wind_given && (r.kind == ManoeuvreKind::kTack || r.kind == ManoeuvreKind::kGybe)) {
      running.push_back(r.kind == ManoeuvreKind::kTack ? r.bisector_deg
                                                       : wrap_360_deg(r.bisector_deg + 180.0));
      WindPoint wp;
      wp.t_s = r.t0_s;
      wp.from_deg = circular_median(running);
      std::vector<double> dev;
      for (double b : running) dev.push_back(std::abs(diff_180_deg(b, wp.from_deg)));
      std::nth_element(dev.begin(), dev.begin() + static_cast<long>(dev.size() / 2), dev.end());
      const double mad = dev[dev.size() / 2];
      wp.n = static_cast<int>(running.size());
      wp.uncertainty_deg = wp.n > 1 ? 1.25 * 1.4826 * mad / std::sqrt(static_cast<double>(wp.n)) : 90.0;
      rep.wind_over_time.push_back(wp);
    }
    rep.manoeuvres.push_back(r);
  }
  if (!rep.wind_given && !rep.wind_over_time.empty())
    rep.wind_uncertainty_deg = rep.wind_over_time.back().uncertainty_deg;
  else if (!rep.wind_given && wind)
    rep.wind_uncertainty_deg = 90.0;
  return rep;
}

std::optional<double> estimate_wind(std::span<const Manoeuvre> list) {
  std::vector<WindTurn> wt;
  for (const auto& m : list)
    wt.push_back({m.course_before_deg, m.turn_dir * m.turn_deg, m.kind == ManoeuvreKind::kPenalty,
                  m.bisector_deg, 0.5 * (m.entry_sog_m_s + m.exit_sog_m_s), std::abs(m.exit_heel_deg)});
  return wind_from_turns(wt);
}

std::vector<ManoeuvreSummary> summarise(const std::vector<Manoeuvre>& list) {
  std::vector<ManoeuvreSummary> out;
  for (auto kind : {ManoeuvreKind::kTack, ManoeuvreKind::kGybe, ManoeuvreKind::kBearAway,
                    ManoeuvreKind::kRoundUp, ManoeuvreKind::kPenalty, ManoeuvreKind::kOther}) {
    ManoeuvreSummary s{kind};
    double sum = 0.0;
    int n = 0;
    s.best_lost_m = kNaN;
    s.worst_lost_m = kNaN;
    for (const auto& m : list) {
      if (m.kind != kind) continue;
      ++s.count;
      if (!std::isfinite(m.distance_lost_m)) continue;
      sum += m.distance_lost_m;
      ++n;
      if (!(m.distance_lost_m >= s.best_lost_m)) s.best_lost_m = m.distance_lost_m;
      if (!(m.distance_lost_m <= s.worst_lost_m)) s.worst_lost_m = m.distance_lost_m;
    }
    s.mean_lost_m = n ? sum / n : kNaN;
    if (s.count) out.push_back(s);
  }
  return out;
}

}  // namespace telltale::fusion
