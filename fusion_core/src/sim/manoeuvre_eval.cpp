// The detector against the simulator's truth (see manoeuvre_eval.hpp).
#include "telltale/fusion/sim/manoeuvre_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/sim/course.hpp"

namespace telltale::fusion::sim {
namespace {
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
                                  const ManoeuvreOptions& options, double match_s,
                                  bool with_heel) {
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
  double turn_sum = 0.0, t0_sum = 0.0, wind_sum = 0.0, lost_sum = 0.0;
  int turn_n = 0;
  for (int i = 0; i < seeds; ++i) {
    const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(i);
    CourseParams p;
    p.drills = true;
    CourseSim course(seed, p);
    std::vector<CourseSample> fixes;
    std::vector<HeelSample> heel;
    std::vector<CourseState> states;  // the truth at every tick
    const int ticks = static_cast<int>(minutes * 600.0);
    for (int k = 0; k <= ticks; ++k) {
      const CourseState s = course.at(k * 0.1);
      fixes.push_back({s.t_s, s.cog_deg, s.sog_m_s});
      heel.push_back({s.t_s, s.heel_deg, 0.0});
      states.push_back(s);
    }
    const auto state_at = [&](double t) -> const CourseState& {
      const long k = std::clamp(std::lround(t * 10.0), 0L, static_cast<long>(states.size()) - 1);
      return states[static_cast<std::size_t>(k)];
    };
    const auto& truth = course.manoeuvres();
    // The wind-free distance lost by its definition (manoeuvres.hpp) on the true motion: u the
    // bisector of the true mean headings over the 15 s before the turn starts and after it ends
    // (cut where the neighbouring manoeuvres turn), the positions without receiver error.
    const auto true_lost = [&](std::size_t j) {
      const TruthManoeuvre& t = truth[j];
      const double from = std::max(t.start_s - 15.0, j > 0 ? truth[j - 1].end_s : 0.0);
      const double to = std::min(t.end_s + 15.0, j + 1 < truth.size() ? truth[j + 1].start_s : 1e18);
      const double h0 = state_at(t.start_s).heading_deg, h1 = h0 + t.turn_deg;
      const auto mean_heading = [&](double a, double b, double ref) {
        double sum = 0.0;
        int n = 0;
        for (double x = a; x < b; x += 0.1, ++n) sum += diff_180_deg(state_at(x).heading_deg, ref);
        return n ? ref + sum / n : ref;
      };
      const double kDeg = M_PI / 180.0;
      const double u = 0.5 * (mean_heading(from, t.start_s, h0) + mean_heading(t.end_s + 0.1, to, h1)) * kDeg;
      const double ue = std::sin(u), un = std::cos(u);
      const auto along = [&](double a, double b) {
        const CourseState &sa = state_at(t.t_s + a), &sb = state_at(t.t_s + b);
        return (sb.east_m - sa.east_m) * ue + (sb.north_m - sa.north_m) * un;
      };
      return along(-20.0, -10.0) / 10.0 * 30.0 - along(-10.0, 20.0);
    };
    const double end_s = ticks * 0.1;
    const ManoeuvreReport rep = analyse_manoeuvres(fixes, with_heel ? std::span<const HeelSample>(heel)
                                                                     : std::span<const HeelSample>(),
                                                           options);
    // Truth scored only where the detector could see it: 25 s of course on either side.
    const auto scorable = [&](double t) { return t > 25.0 && t < end_s - 25.0; };
    std::vector<bool> used(rep.manoeuvres.size(), false);
    for (std::size_t ti = 0; ti < truth.size(); ++ti) {
      const TruthManoeuvre& t = truth[ti];
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
          // A matched tack or gybe measured off the truth: "seed S: tack at T s turn D, true D".
          const auto off = [&](const char* what, double got, double truth_v) {
            char line[160];
            std::snprintf(line, sizeof line, "seed %llu: %s at %.1f s %s %.2f, true %.2f",
                          static_cast<unsigned long long>(seed), to_string(t.kind), t.t_s, what,
                          got, truth_v);
            ev.misses.emplace_back(line);
          };
          if (e > 5.0) off("turn", d.turn_deg, t.turn_deg);
          t0_sum += std::abs(d.t0_s - t.t_s);
          const double le = std::abs(d.distance_lost_m - true_lost(ti));
          lost_sum += le;
          ev.lost_err_max_m = std::max(ev.lost_err_max_m, le);
          if (le > 2.0) off("lost (m)", d.distance_lost_m, true_lost(ti));
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
    const double we =
        rep.wind_from_deg ? std::abs(diff_180_deg(*rep.wind_from_deg, p.wind_from_deg)) : 180.0;
    wind_sum += we;
    ev.wind_err_max_deg = std::max(ev.wind_err_max_deg, we);
  }
  for (KindScore* sc : {&ev.tack, &ev.gybe, &ev.bear_away, &ev.round_up, &ev.penalty})
    sc->detected += sc->matched;
  ev.turn_err_mean_deg = turn_n ? turn_sum / turn_n : 0.0;
  ev.t0_err_mean_s = turn_n ? t0_sum / turn_n : 0.0;
  ev.lost_err_mean_m = turn_n ? lost_sum / turn_n : 0.0;
  ev.wind_err_mean_deg = seeds ? wind_sum / seeds : 0.0;
  return ev;
}

}  // namespace telltale::fusion::sim
