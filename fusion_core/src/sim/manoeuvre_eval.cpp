// The detector against the simulator's truth (see manoeuvre_eval.hpp).
#include "telltale/fusion/sim/manoeuvre_eval.hpp"

#include <cmath>
#include <cstdio>

#include "telltale/fusion/sim/course.hpp"

namespace telltale::fusion::sim {
namespace {
double diff180(double a, double b) {
  double d = std::fmod(a - b + 540.0, 360.0) - 180.0;
  return d == -180.0 ? 180.0 : d;
}
ManoeuvreKind as_detected(TruthKind k) {
  switch (k) {
    case TruthKind::kTack: return ManoeuvreKind::kTack;
    case TruthKind::kGybe: return ManoeuvreKind::kGybe;
    case TruthKind::kBearAway: return ManoeuvreKind::kBearAway;
    case TruthKind::kRoundUp: return ManoeuvreKind::kRoundUp;
    case TruthKind::kPenalty: return ManoeuvreKind::kPenalty;
    case TruthKind::kRounding: return ManoeuvreKind::kOther;
  }
  return ManoeuvreKind::kOther;
}
}  // namespace

ManoeuvreEval evaluate_manoeuvres(std::uint64_t first_seed, int seeds, double minutes,
                                  const ManoeuvreOptions& options, double match_s) {
  ManoeuvreEval ev;
  const auto score = [&](ManoeuvreKind k) -> KindScore* {
    switch (k) {
      case ManoeuvreKind::kTack: return &ev.tack;
      case ManoeuvreKind::kGybe: return &ev.gybe;
      case ManoeuvreKind::kBearAway: return &ev.bear_away;
      case ManoeuvreKind::kRoundUp: return &ev.round_up;
      case ManoeuvreKind::kPenalty: return &ev.penalty;
      default: return nullptr;
    }
  };
  double turn_sum = 0.0, t0_sum = 0.0, wind_sum = 0.0;
  int turn_n = 0;
  for (int i = 0; i < seeds; ++i) {
    const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(i);
    CourseParams p;
    p.drills = true;
    CourseSim course(seed, p);
    std::vector<CourseSample> fixes;
    std::vector<HeelSample> heel;
    const int ticks = static_cast<int>(minutes * 600.0);
    for (int k = 0; k <= ticks; ++k) {
      const CourseState s = course.at(k * 0.1);
      fixes.push_back({s.t_s, s.cog_deg, s.sog_m_s});
      heel.push_back({s.t_s, s.heel_deg, 0.0});
    }
    const double end_s = ticks * 0.1;
    const ManoeuvreReport rep = analyse_manoeuvres(fixes, heel, options);
    const auto& truth = course.manoeuvres();
    // Truth scored only where the detector could see it: 25 s of course on either side.
    const auto scorable = [&](double t) { return t > 25.0 && t < end_s - 25.0; };
    std::vector<bool> used(rep.manoeuvres.size(), false);
    for (const auto& t : truth) {
      if (!scorable(t.t_s)) continue;
      if (t.kind == TruthKind::kRounding) {
        ++ev.roundings;
        continue;
      }
      const ManoeuvreKind want = as_detected(t.kind);
      KindScore* sc = score(want);
      ++sc->truth;
      bool found = false;
      for (std::size_t j = 0; j < rep.manoeuvres.size(); ++j) {
        const auto& d = rep.manoeuvres[j];
        if (used[j] || d.kind != want || std::abs(d.t0_s - t.t_s) > match_s) continue;
        used[j] = true;
        found = true;
        ++sc->matched;
        if (want == ManoeuvreKind::kTack || want == ManoeuvreKind::kGybe) {
          const double e = std::abs(d.turn_deg - std::abs(t.turn_deg));
          turn_sum += e;
          ev.turn_err_max_deg = std::max(ev.turn_err_max_deg, e);
          if (e > 5.0) {
            char line[160];
            std::snprintf(line, sizeof line, "seed %llu: %s at %.1f s turn %.1f, true %.1f",
                          static_cast<unsigned long long>(seed), to_string(t.kind), t.t_s,
                          d.turn_deg, t.turn_deg);
            ev.misses.emplace_back(line);
          }
          t0_sum += std::abs(d.t0_s - t.t_s);
          ++turn_n;
        }
        break;
      }
      if (!found) {
        char line[160];
        std::snprintf(line, sizeof line, "seed %llu: missed %s at %.1f s (turn %.0f)",
                      static_cast<unsigned long long>(seed), to_string(t.kind), t.t_s, t.turn_deg);
        ev.misses.emplace_back(line);
      }
    }
    for (std::size_t j = 0; j < rep.manoeuvres.size(); ++j) {
      const auto& d = rep.manoeuvres[j];
      if (used[j] || !scorable(d.t0_s)) continue;
      bool rounding = false;
      for (const auto& t : truth)
        if (t.kind == TruthKind::kRounding && std::abs(d.t0_s - t.t_s) <= match_s) rounding = true;
      if (rounding) continue;
      if (KindScore* sc = score(d.kind)) {
        ++sc->detected;  // a false one (matched ones are counted below)
        char line[160];
        std::snprintf(line, sizeof line, "seed %llu: false %s at %.1f s (turn %.0f)",
                      static_cast<unsigned long long>(seed), to_string(d.kind), d.t0_s, d.turn_deg);
        ev.misses.emplace_back(line);
      }
    }
    for (KindScore* sc : {&ev.tack, &ev.gybe, &ev.bear_away, &ev.round_up, &ev.penalty})
      (void)sc;
    const double we = rep.wind_from_deg ? std::abs(diff180(*rep.wind_from_deg, p.wind_from_deg)) : 180.0;
    wind_sum += we;
    ev.wind_err_max_deg = std::max(ev.wind_err_max_deg, we);
  }
  for (KindScore* sc : {&ev.tack, &ev.gybe, &ev.bear_away, &ev.round_up, &ev.penalty})
    sc->detected += sc->matched;
  ev.turn_err_mean_deg = turn_n ? turn_sum / turn_n : 0.0;
  ev.t0_err_mean_s = turn_n ? t0_sum / turn_n : 0.0;
  ev.wind_err_mean_deg = seeds ? wind_sum / seeds : 0.0;
  return ev;
}

}  // namespace telltale::fusion::sim
