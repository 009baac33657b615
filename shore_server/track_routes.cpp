// Positions in the REST API (see track_routes.hpp).
#include "track_routes.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "json_views.hpp"
#include "route_helpers.hpp"
#include "sailing_stats.hpp"

namespace telltale::shore {

using nlohmann::json;

FixJoin::FixJoin(Store& store, std::string boat_id, std::uint64_t from_ns, std::uint64_t to_ns)
    : store_(store),
      boat_id_(std::move(boat_id)),
      to_ns_(to_ns),
      after_ns_(from_ns > kFixJoinMaxAgeNs ? from_ns - kFixJoinMaxAgeNs : 0) {}

void FixJoin::refill() {
  constexpr std::size_t kPage = 2000;
  page_ = store_.fix_page(boat_id_, after_ns_, to_ns_, kPage);
  next_ = 0;
  if (page_.empty()) {
    exhausted_ = true;
  } else {
    after_ns_ = page_.back().t_utc_ns;
  }
}

const FixSample* FixJoin::at(std::uint64_t t_ns) {
  for (;;) {
    if (next_ >= page_.size()) {
      if (exhausted_) break;
      refill();
      if (exhausted_) break;
    }
    if (page_[next_].t_utc_ns > t_ns) break;
    current_ = page_[next_++];
  }
  if (!current_ || current_->t_utc_ns > t_ns || t_ns - current_->t_utc_ns > kFixJoinMaxAgeNs)
    return nullptr;
  return &*current_;
}

namespace {

/// `v` with `decimals` digits after the point; empty when not finite.
std::string num(double v, int decimals = 3) {
  if (!std::isfinite(v)) return "";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

SessionInfo session_or_404(ShoreContext& ctx, const httplib::Request& req, const Principal& p) {
  const std::int64_t id = path_number(req, "session");
  auto s = ctx.store.session(id);
  if (!s) throw HttpError(404, "unknown session " + std::to_string(id));
  require_boat(p, s->boat_id);
  return *s;
}

/// GPX 1.1 of a session: one track, one segment, a point per stored fix with a position, each
/// with its time and, in the Telltale extension namespace, the heel and pitch of the attitude
/// sample nearest before it (within 1 s) and the fix's SOG and COG (GPX 1.1 has no speed).
void stream_gpx(httplib::Response& res, Store& store, const SessionInfo& s) {
  struct Cursor {
    std::uint64_t after_fix;
    std::uint64_t after_att;
    std::vector<AttitudeRow> att;
    std::size_t att_i = 0;
    std::optional<AttitudeRow> last_att;
    bool started = false;
    bool done = false;
  };
  auto c = std::make_shared<Cursor>();
  c->after_fix = s.start_ns == 0 ? 0 : s.start_ns - 1;
  c->after_att = s.start_ns > 1000000000ULL ? s.start_ns - 1000000000ULL : 0;
  char name[96];
  std::snprintf(name, sizeof name, "telltale_%s_session%lld.gpx", s.boat_id.c_str(),
                static_cast<long long>(s.id));
  res.set_header("Content-Disposition", std::string("attachment; filename=\"") + name + "\"");
  res.set_chunked_content_provider(
      "application/gpx+xml", [&store, s, c](std::size_t, httplib::DataSink& sink) {
        std::string out;
        if (!c->started) {
          c->started = true;
          out =
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<gpx version=\"1.1\" creator=\"Telltale\" "
              "xmlns=\"http://www.topografix.com/GPX/1/1\" xmlns:tt=\"urn:telltale:gpx:1\">\n"
              "<metadata><name>" +
              s.boat_id + " session " + std::to_string(s.id) + "</name><time>" +
              iso8601(s.start_ns) + "</time></metadata>\n<trk><name>" + s.boat_id +
              "</name><trkseg>\n";
        }
        if (c->done) {
          sink.done();
          return true;
        }
        constexpr std::size_t kPage = 2000;
        const auto fixes = store.fix_page(s.boat_id, c->after_fix, s.end_ns, kPage);
        for (const auto& f : fixes) {
          // Attitude up to this fix's time.
          for (;;) {
            if (c->att_i >= c->att.size()) {
              c->att = store.attitude_page(s.boat_id, c->after_att, f.t_utc_ns, 4000);
              c->att_i = 0;
              if (c->att.empty()) break;
              c->after_att = c->att.back().t_utc_ns;
            }
            if (c->att[c->att_i].t_utc_ns > f.t_utc_ns) break;
            c->last_att = c->att[c->att_i++];
          }
          out += "<trkpt lat=\"" + num(f.lat_deg, 7) + "\" lon=\"" + num(f.lon_deg, 7) +
                 "\"><time>" + iso8601(f.t_utc_ns) + "</time><extensions>";
          if (c->last_att && f.t_utc_ns - c->last_att->t_utc_ns <= 1000000000ULL)
            out += "<tt:heel_deg>" + num(c->last_att->heel_deg, 2) + "</tt:heel_deg><tt:pitch_deg>" +
                   num(c->last_att->pitch_deg, 2) + "</tt:pitch_deg>";
          if (std::isfinite(f.sog_m_s)) out += "<tt:sog_m_s>" + num(f.sog_m_s) + "</tt:sog_m_s>";
          if (std::isfinite(f.cog_deg)) out += "<tt:cog_deg>" + num(f.cog_deg, 1) + "</tt:cog_deg>";
          out += "</extensions></trkpt>\n";
        }
        if (!fixes.empty()) c->after_fix = fixes.back().t_utc_ns;
        if (fixes.size() < kPage) {
          c->done = true;
          out += "</trkseg></trk>\n</gpx>\n";
        }
        return out.empty() || sink.write(out.data(), out.size());
      });
}

json bands_json(const HeelSpeed::Bands& bands) {
  json arr = json::array();
  for (const auto& b : bands)
    arr.push_back({{"from_deg", b.from_deg},
                   {"to_deg", b.to_deg},
                   {"seconds", b.seconds},
                   {"mean_sog_m_s", finite_or_null(b.mean_sog_m_s)}});
  return arr;
}

}  // namespace

void register_track_routes(httplib::Server& server, ShoreContext& ctx) {
  server.Get(R"(/api/v1/boats/([^/]+)/track)", [&ctx](const httplib::Request& req,
                                                      httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"from", "to", "max_points"});
    const std::string id = path_id(req, "boat");
    require_boat(p, id);
    const TimeRange range = parse_range(param(req, "from"), param(req, "to"));
    std::size_t max_points = 5000;
    if (const std::string* m = param(req, "max_points")) {
      const auto n = parse_int(*m, 2, 100000);
      if (!n) throw HttpError(400, "max_points must be an integer in 2..100000");
      max_points = static_cast<std::size_t>(*n);
    }
    if (!ctx.fleet.boat(id) && !ctx.store.knows_boat(id))
      throw HttpError(404, "unknown boat '" + id + "'");
    const auto points = ctx.store.track(id, range.from_ns, range.to_ns, max_points);
    // One array per exported field of the fix (sample_fields.hpp), as the sample exports have,
    // written straight to text as the attitude's chart columns are.
    std::string out =
        "{\"boat_id\":" + to_json_text(id) + ",\"points\":" + std::to_string(points.size());
    append_number_column(out, "t_s", points,
                         [](const FixSample& f) { return static_cast<double>(f.t_utc_ns) * 1e-9; });
    for_each_field<kExported>(kFixFields, [&](const auto& field) {
      static_assert(std::is_floating_point_v<
                        std::remove_cvref_t<decltype(field.get(std::declval<const FixSample&>()))>>,
                    "the track's columns are numbers");
      append_number_column(out, field.name, points,
                           [&](const FixSample& f) { return field.get(f); });
    });
    res.set_content(out + "}", "application/json");
  });

  server.Get(R"(/api/v1/sessions/([^/]+)/gpx)", [&ctx](const httplib::Request& req,
                                                      httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {});
    stream_gpx(res, ctx.store, session_or_404(ctx, req, p));
  });

  server.Get(R"(/api/v1/sessions/([^/]+)/heel_speed)", [&ctx](const httplib::Request& req,
                                                             httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"wind_from_deg"});
    std::optional<double> wind;
    if (const std::string* w = param(req, "wind_from_deg")) {
      const auto n = parse_int(*w, 0, 359);
      if (!n) throw HttpError(400, "wind_from_deg must be a whole number of degrees in 0..359");
      wind = static_cast<double>(*n);
    }
    const SessionInfo s = session_or_404(ctx, req, p);
    // Every attitude sample stands for the time to the next one (at most 1 s, as the heel
    // bands), joined with the fix current then.
    std::vector<SailingPoint> pts;
    FixJoin fixes(ctx.store, s.boat_id, s.start_ns, s.end_ns);
    std::optional<AttitudeRow> prev;
    const auto add = [&](const AttitudeRow& r, double dt) {
      SailingPoint pt;
      pt.dt_s = dt;
      pt.heel_deg = r.heel_deg;
      const FixSample* f = fixes.at(r.t_utc_ns);
      pt.sog_m_s = f ? f->sog_m_s : std::nan("");
      pt.cog_deg = f ? f->cog_deg : std::nan("");
      pts.push_back(pt);
    };
    ctx.store.visit_attitude(s.boat_id, s.start_ns, s.end_ns, [&](const AttitudeRow& r) {
      if (prev) add(*prev, std::min(1.0, static_cast<double>(r.t_utc_ns - prev->t_utc_ns) * 1e-9));
      prev = r;
      return true;
    });
    const HeelSpeed hs = heel_speed(pts, wind);
    res.set_content(
        to_json_text({{"session_id", s.id},
                      {"boat_id", s.boat_id},
                      {"wind_from_deg", hs.wind_from_deg ? json(*hs.wind_from_deg) : json(nullptr)},
                      {"wind_estimated", hs.wind_estimated},
                      {"upwind", {{"port", bands_json(hs.upwind_port)},
                                  {"starboard", bands_json(hs.upwind_starboard)}}},
                      {"downwind", {{"port", bands_json(hs.downwind_port)},
                                    {"starboard", bands_json(hs.downwind_starboard)}}},
                      {"reaching_s", hs.reaching_s},
                      {"slow_s", hs.slow_s},
                      {"no_fix_s", hs.no_fix_s},
                      {"unsplit_s", hs.unsplit_s},
                      {"total_s", hs.total_s}}),
        "application/json");
  });
}

}  // namespace telltale::shore
