// Manoeuvres in the REST API (see manoeuvre_routes.hpp).
#include "manoeuvre_routes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <vector>

#include "json_views.hpp"
#include "query.hpp"
#include "route_helpers.hpp"
#include "store.hpp"
#include "telltale/fusion/manoeuvres.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::shore {

using nlohmann::json;

namespace {

std::string num(double v, int decimals = 3) {
  if (!std::isfinite(v)) return "";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// With `from`: the data read from this long before it, so a manoeuvre at `from` has its
// detection windows (10 s of course either side) and its metrics' (20 s before t0) complete.
constexpr std::uint64_t kLookbackNs = 45'000'000'000ULL;

/// The boat's wind instrument over a stretch (telltale/fusion/wind.hpp wind_mean), with the
/// median speed and the number of readings.
struct InstrumentWind {
  double from_deg = 0.0, spread_deg = 0.0, speed_m_s = std::nan("");
  std::size_t n = 0;
};
std::optional<InstrumentWind> instrument_wind(std::span<const WindSample> rows) {
  std::vector<double> dirs, speeds;
  dirs.reserve(rows.size());
  for (const auto& w : rows) {
    dirs.push_back(w.from_deg);
    if (std::isfinite(w.speed_m_s)) speeds.push_back(w.speed_m_s);
  }
  const auto mean = fusion::wind_mean(dirs);
  if (!mean) return std::nullopt;
  InstrumentWind out{mean->from_deg, mean->spread_deg, std::nan(""), rows.size()};
  if (!speeds.empty()) {
    const auto mid = speeds.begin() + static_cast<std::ptrdiff_t>(speeds.size() / 2);
    std::nth_element(speeds.begin(), mid, speeds.end());
    out.speed_m_s = *mid;
  }
  return out;
}

std::uint64_t to_ns(std::uint64_t base_ns, double t_s) {
  return base_ns + static_cast<std::uint64_t>(std::llround(std::max(0.0, t_s) * 1e9));
}

}  // namespace

json manoeuvre_object(const fusion::Manoeuvre& m, std::uint64_t t0_utc_ns) {
  return {{"kind", fusion::to_string(m.kind)},
          {"t_utc", iso8601(t0_utc_ns)},
          {"turn_deg", finite_or_null(m.turn_deg)},
          {"turn_dir", m.turn_dir},
          {"distance_lost_m", finite_or_null(m.distance_lost_m)},
          {"vmg_lost_m", finite_or_null(m.vmg_lost_m)},
          {"heel_peak_deg", finite_or_null(m.heel_peak_deg)},
          {"heel_peak_windward_deg", finite_or_null(m.heel_peak_windward_deg)},
          {"heel_peak_leeward_deg", finite_or_null(m.heel_peak_leeward_deg)},
          {"heel_zero_s", finite_or_null(m.heel_zero_s)},
          {"exit_heel_deg", finite_or_null(m.exit_heel_deg)},
          {"entry_sog_m_s", finite_or_null(m.entry_sog_m_s)},
          {"min_sog_m_s", finite_or_null(m.min_sog_m_s)},
          {"exit_sog_m_s", finite_or_null(m.exit_sog_m_s)},
          {"speed_loss_m_s", finite_or_null(m.speed_loss_m_s)},
          {"turn_duration_s", finite_or_null(m.turn_duration_s)},
          {"recovery_s", finite_or_null(m.recovery_s)},
          {"max_turn_rate_deg_s", finite_or_null(m.max_turn_rate_deg_s)},
          {"mean_turn_rate_deg_s", finite_or_null(m.mean_turn_rate_deg_s)},
          {"pitch_min_deg", finite_or_null(m.pitch_min_deg)},
          {"pitch_max_deg", finite_or_null(m.pitch_max_deg)},
          {"pitch_mean_deg", finite_or_null(m.pitch_mean_deg)},
          {"course_before_deg", finite_or_null(m.course_before_deg)},
          {"course_after_deg", finite_or_null(m.course_after_deg)},
          {"unsteady_entry", m.unsteady_entry},
          {"heel_flip_agrees", m.heel_flip_agrees ? json(*m.heel_flip_agrees) : json(nullptr)}};
}

void register_manoeuvre_routes(httplib::Server& server, ShoreContext& ctx) {
  server.Get(R"(/api/v1/sessions/([^/]+)/manoeuvres)", [&ctx](const httplib::Request& req,
                                                             httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"format", "wind_from_deg", "from"});
    bool csv = false;
    if (const std::string* f = param(req, "format")) {
      if (*f == "csv") csv = true;
      else if (*f != "json") throw HttpError(400, "format must be json or csv");
    }
    fusion::ManoeuvreOptions opt;
    if (const std::string* w = param(req, "wind_from_deg")) {
      const auto n = parse_int(*w, 0, 359);
      if (!n) throw HttpError(400, "wind_from_deg must be a whole number of degrees in 0..359");
      opt.wind_from_deg = static_cast<double>(*n);
    }
    const std::int64_t id = path_number(req, "session");
    const auto s = ctx.store.session(id);
    if (!s) throw HttpError(404, "unknown session " + std::to_string(id));
    require_boat(p, s->boat_id);
    // Times in seconds from the session's start (double keeps sub-microsecond precision).
    const std::uint64_t base = s->start_ns;
    const auto rel = [base](std::uint64_t t) {
      return t >= base ? static_cast<double>(t - base) * 1e-9 : -static_cast<double>(base - t) * 1e-9;
    };
    // `from` (the fleet view filling in a live boat when it opens): only the manoeuvres from
    // then, read from the data of the 45 s before it on, not the whole session.
    const std::string* from_param = param(req, "from");
    const std::uint64_t from_ns = from_param ? parse_range(from_param, nullptr).from_ns : 0;
    const std::uint64_t read_from = std::max(s->start_ns, from_ns > kLookbackNs ? from_ns - kLookbackNs : 0);
    std::vector<fusion::CourseSample> fixes;
    std::uint64_t data_to = 0;
    ctx.store.visit_fixes(s->boat_id, read_from, s->end_ns, [&](const FixSample& f) {
      fixes.push_back({rel(f.t_utc_ns), f.cog_deg, f.sog_m_s});
      data_to = f.t_utc_ns;
      return true;
    });
    std::vector<fusion::HeelSample> heel;
    ctx.store.visit_attitude(s->boat_id, read_from, s->end_ns, [&](const AttitudeRow& r) {
      heel.push_back({rel(r.t_utc_ns), r.heel_deg, r.pitch_deg});
      return true;
    });
    // The wind, in order of trust: the coach's (the query), the boat's wind instrument (its
    // stored readings: live BoatWind or an imported log's), else the estimate from the tacks. When the wind is given either way the
    // estimate is still made, and reported beside it: how far the track's own estimate is off.
    const char* wind_source = opt.wind_from_deg ? "coach" : "estimated";
    std::optional<InstrumentWind> instrument;
    std::vector<WindSample> readings;
    if (!opt.wind_from_deg) {
      readings = ctx.store.wind(s->boat_id, read_from, s->end_ns, 50000);
      instrument = instrument_wind(readings);
      if (instrument) {
        opt.wind_from_deg = instrument->from_deg;
        wind_source = "instrument";
        // Each manoeuvre against the wind of its own time: the readings of the 2 minutes
        // either side of its t0 (a shift is minutes long; a gust's swing averages out).
        opt.wind_at = [&readings, &rel](double t_s) -> std::optional<double> {
          constexpr double kHalfS = 120.0;
          const auto lo = std::lower_bound(
              readings.begin(), readings.end(), t_s - kHalfS,
              [&](const WindSample& w, double t) { return rel(w.t_utc_ns) < t; });
          const auto hi = std::upper_bound(
              lo, readings.end(), t_s + kHalfS,
              [&](double t, const WindSample& w) { return t < rel(w.t_utc_ns); });
          const auto here = instrument_wind(std::span<const WindSample>(lo, hi));
          if (!here) return std::nullopt;
          return here->from_deg;
        };
      }
    }
    fusion::ManoeuvreReport rep = fusion::analyse_manoeuvres(fixes, heel, opt);
    // The estimate beside a given wind: for the review (JSON, the whole session), not for a CSV
    // nor for the fleet view's `from` stretch (45 s: no estimate to speak of), which would only
    // run the detector twice on every open.
    std::optional<fusion::ManoeuvreReport> estimate;
    if (rep.wind_given && !csv && !from_param)
      estimate = fusion::analyse_manoeuvres(fixes, heel, fusion::ManoeuvreOptions{});
    const fusion::ManoeuvreReport& est = estimate ? *estimate : rep;
    if (from_param)
      std::erase_if(rep.manoeuvres, [&](const fusion::Manoeuvre& m) { return to_ns(base, m.t0_s) < from_ns; });
    if (csv) {
      std::string out =
          "kind,t_utc,turn_deg,turn_dir,distance_lost_m,vmg_lost_m,heel_peak_deg,"
          "heel_peak_windward_deg,heel_peak_leeward_deg,heel_zero_s,exit_heel_deg,entry_sog_m_s,"
          "min_sog_m_s,exit_sog_m_s,speed_loss_m_s,turn_duration_s,recovery_s,"
          "max_turn_rate_deg_s,mean_turn_rate_deg_s,pitch_min_deg,pitch_max_deg,pitch_mean_deg,"
          "course_before_deg,course_after_deg,unsteady_entry,heel_flip_agrees\n";
      for (const auto& m : rep.manoeuvres) {
        out += std::string(fusion::to_string(m.kind)) + "," + iso8601(to_ns(base, m.t0_s)) + "," +
               num(m.turn_deg, 1) + "," + std::to_string(m.turn_dir) + "," +
               num(m.distance_lost_m, 2) + "," + num(m.vmg_lost_m, 2) + "," +
               num(m.heel_peak_deg, 1) + "," + num(m.heel_peak_windward_deg, 1) + "," +
               num(m.heel_peak_leeward_deg, 1) + "," + num(m.heel_zero_s, 2) + "," +
               num(m.exit_heel_deg, 1) + "," + num(m.entry_sog_m_s) + "," + num(m.min_sog_m_s) +
               "," + num(m.exit_sog_m_s) + "," + num(m.speed_loss_m_s) + "," +
               num(m.turn_duration_s, 2) + "," + num(m.recovery_s, 2) + "," +
               num(m.max_turn_rate_deg_s, 1) + "," + num(m.mean_turn_rate_deg_s, 1) + "," +
               num(m.pitch_min_deg, 1) + "," + num(m.pitch_max_deg, 1) + "," +
               num(m.pitch_mean_deg, 1) + "," + num(m.course_before_deg, 1) + "," +
               num(m.course_after_deg, 1) + "," + (m.unsteady_entry ? "1" : "0") + "," +
               (m.heel_flip_agrees ? (*m.heel_flip_agrees ? "1" : "0") : "") + "\n";
      }
      res.set_content(out, "text/csv");
      return;
    }
    json list = json::array();
    for (const auto& m : rep.manoeuvres) {
      list.push_back(manoeuvre_object(m, to_ns(base, m.t0_s)));
    }
    json summary = json::array();
    for (const auto& k : fusion::summarise(rep.manoeuvres))
      summary.push_back({{"kind", fusion::to_string(k.kind)},
                         {"count", k.count},
                         {"mean_distance_lost_m", finite_or_null(k.mean_lost_m)},
                         {"best_distance_lost_m", finite_or_null(k.best_lost_m)},
                         {"worst_distance_lost_m", finite_or_null(k.worst_lost_m)}});
    json wind_t = json::array();
    for (const auto& w : est.wind_over_time)
      wind_t.push_back({{"t_utc", iso8601(to_ns(base, w.t_s))},
                        {"from_deg", w.from_deg},
                        {"uncertainty_deg", w.uncertainty_deg},
                        {"n", w.n}});
    json wind_json = {
        {"from_deg", rep.wind_from_deg ? json(*rep.wind_from_deg) : json(nullptr)},
        {"given", rep.wind_given},
        {"source", rep.wind_from_deg ? json(wind_source) : json(nullptr)},
        {"uncertainty_deg", rep.wind_from_deg ? json(rep.wind_uncertainty_deg) : json(nullptr)},
        {"over_time", std::move(wind_t)},
        {"instrument", nullptr},
        {"estimated_from_deg", est.wind_from_deg ? json(*est.wind_from_deg) : json(nullptr)},
        {"estimated_uncertainty_deg",
         est.wind_from_deg ? json(est.wind_uncertainty_deg) : json(nullptr)},
        {"estimate_error_deg", nullptr}};
    if (instrument) {
      wind_json["instrument"] = {{"from_deg", instrument->from_deg},
                                 {"spread_deg", instrument->spread_deg},
                                 {"speed_m_s", finite_or_null(instrument->speed_m_s)},
                                 {"readings", instrument->n}};
      if (est.wind_from_deg)
        wind_json["estimate_error_deg"] =
            std::remainder(*est.wind_from_deg - instrument->from_deg, 360.0);
    }
    res.set_content(to_json_text({{"session_id", s->id},
                                  {"boat_id", s->boat_id},
                                  {"from_utc", from_param ? json(iso8601(from_ns)) : json(nullptr)},
                                  {"data_to_utc", data_to ? json(iso8601(data_to)) : json(nullptr)},
                                  {"wind", wind_json},
                                  {"manoeuvres", std::move(list)},
                                  {"summary", std::move(summary)}}),
                    "application/json");
  });
}

}  // namespace telltale::shore
