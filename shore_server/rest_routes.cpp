// The data routes of the REST API: boats, sessions, attitude ranges, exports, alarms.
// Every input is parsed strictly (query.hpp); every failure is an HttpError with its 4xx.
#include <httplib.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "http_api.hpp"
#include "json_views.hpp"
#include "query.hpp"
#include "route_helpers.hpp"
#include "track_routes.hpp"
#include "shutdown.hpp"

namespace telltale::shore {
namespace {

/// The fleet as a coach's GET /boats returns it, rebuilt at most every kMaxAge: a dashboard or a
/// tool polling /boats gets the fleet as of at most 100 ms ago (the live stream is the fast path),
/// and a thousand polls a second cost one build per tick instead of one each (0.5 ms per build
/// with 200 boats).
class BoatsSnapshot {
 public:
  static constexpr std::chrono::milliseconds kMaxAge{100};

  std::shared_ptr<const std::string> get(const FleetModel& fleet) {
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (!text_ || now - built_ >= kMaxAge) {
      text_ = std::make_shared<const std::string>(boats_json(fleet.boats()));
      built_ = now;
    }
    return text_;
  }

 private:
  std::mutex mutex_;
  std::shared_ptr<const std::string> text_;
  std::chrono::steady_clock::time_point built_{};
};

using nlohmann::json;

constexpr std::int64_t kMaxPointsLimit = 100000;

enum class Format { kJson, kCsv };
Format format_of(const httplib::Request& req) {
  const std::string* f = param(req, "format");
  if (!f || *f == "json") return Format::kJson;
  if (*f == "csv") return Format::kCsv;
  throw HttpError(400, "format must be json or csv");
}

std::optional<std::size_t> max_points_of(const httplib::Request& req) {
  const std::string* m = param(req, "max_points");
  if (!m) return std::nullopt;
  const auto n = parse_int(*m, 4, kMaxPointsLimit);
  if (!n)
    throw HttpError(400, "max_points must be an integer in 4.." + std::to_string(kMaxPointsLimit));
  return static_cast<std::size_t>(*n);
}

std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string csv_coordinate(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.7f", v);
  return buf;
}

/// ",cell" for every exported field of `table` (sample_fields.hpp); empty cells without a record.
template <class Table, class Record>
void add_csv_cells(std::string& out, const Table& table, const Record* record) {
  for_each_field<kExported>(table, [&](const auto& f) {
    out += ',';
    if (!record) return;
    const auto& v = f.get(*record);
    using T = std::remove_cvref_t<decltype(v)>;
    if constexpr (std::is_floating_point_v<T>) {
      out += f.csv == CsvFormat::kCoordinate ? csv_coordinate(static_cast<double>(v))
                                             : csv_number(static_cast<double>(v));
    } else if constexpr (std::is_same_v<T, std::string>) {
      // Quoted when it holds a comma, a quote or a line break.
      if (v.find_first_of(",\"\r\n") == std::string::npos) {
        out += v;
      } else {
        out += '"';
        for (const char c : v) out += c == '"' ? std::string("\"\"") : std::string(1, c);
        out += '"';
      }
    } else {
      out += std::to_string(v);
    }
  });
}

/// The sample exports' columns: the sample's time, its exported fields, then those of the fix
/// current at its time.
const std::string& csv_header() {
  static const std::string kHeader = "time_utc,t_s," +
                                     field_names<kExported>(kAttitudeFields, ",") + "," +
                                     field_names<kExported>(kFixFields, ",") + "\n";
  return kHeader;
}

/// One attitude sample with the fix current at its time (empty position columns without one).
std::string csv_row(const AttitudeRow& r, const FixSample* f) {
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", static_cast<double>(r.t_utc_ns) * 1e-9);
  std::string out = iso8601(r.t_utc_ns) + "," + t;
  add_csv_cells(out, kAttitudeFields, &r);
  add_csv_cells(out, kFixFields, f);
  return out + "\n";
}

void append_row_json(std::string& out, const AttitudeRow& r, const FixSample* f) {
  JsonObjectText o(out);
  o.string("time_utc", iso8601(r.t_utc_ns));
  o.number("t_s", static_cast<double>(r.t_utc_ns) * 1e-9);
  o.exported(kAttitudeFields, &r);
  o.exported(kFixFields, f);
}

/// Streams every stored sample of a boat in [from, to] as CSV or JSON, a page at a time: a long
/// session is never held in memory whole. Each sample carries the fix current at its time.
void stream_rows(httplib::Response& res, Store& store, const std::string& boat_id,
                 std::uint64_t from_ns, std::uint64_t to_ns, Format format, json head,
                 const std::string& filename) {
  if (!filename.empty())
    res.set_header("Content-Disposition", "attachment; filename=\"" + filename + "\"");
  struct Cursor {
    std::uint64_t after = 0;
    bool started = false;
    bool first_row = true;
    bool done = false;
    std::unique_ptr<FixJoin> fixes;
  };
  auto cursor = std::make_shared<Cursor>();
  cursor->after = from_ns == 0 ? 0 : from_ns - 1;
  cursor->fixes = std::make_unique<FixJoin>(store, boat_id, from_ns, to_ns);
  res.set_chunked_content_provider(
      format == Format::kCsv ? "text/csv" : "application/json",
      [&store, boat_id, to_ns, format, cursor, head = std::move(head)](std::size_t,
                                                                       httplib::DataSink& sink) {
        std::string out;
        if (!cursor->started) {
          cursor->started = true;
          if (format == Format::kCsv) {
            out = csv_header();
          } else {
            std::string h = to_json_text(head);
            h.pop_back();  // reopen the object to append the samples array
            out = h + (head.empty() ? "" : ",") + "\"samples\":[";
          }
        }
        if (cursor->done) {
          sink.done();
          return true;
        }
        constexpr std::size_t kPage = 2000;
        const auto rows = store.attitude_page(boat_id, cursor->after, to_ns, kPage);
        for (const auto& r : rows) {
          const FixSample* fix = cursor->fixes->at(r.t_utc_ns);
          if (format == Format::kCsv) {
            out += csv_row(r, fix);
          } else {
            if (!cursor->first_row) out += ",";
            append_row_json(out, r, fix);
            cursor->first_row = false;
          }
        }
        if (!rows.empty()) cursor->after = rows.back().t_utc_ns;
        if (rows.size() < kPage) {
          cursor->done = true;
          if (format == Format::kJson) out += "]}";
        }
        return out.empty() || sink.write(out.data(), out.size());
      });
}

/// A chart's thinning: the time span cut into buckets, each keeping the samples with the lowest
/// and highest heel and pitch (at most 4), so peaks survive downsampling.
class ChartThinner {
 public:
  ChartThinner(std::uint64_t first_ns, std::uint64_t last_ns, std::size_t buckets)
      : first_ns_(first_ns),
        span_(static_cast<double>(last_ns - first_ns) + 1.0),
        extremes_(buckets),
        used_(buckets, false) {}

  void add(const AttitudeRow& r) {
    const std::size_t buckets = extremes_.size();
    auto b = static_cast<std::size_t>(static_cast<double>(r.t_utc_ns - first_ns_) / span_ *
                                      static_cast<double>(buckets));
    b = std::min(b, buckets - 1);
    auto& e = extremes_[b];
    if (!used_[b]) {
      e = {r, r, r, r};
      used_[b] = true;
      return;
    }
    if (r.heel_deg < e[0].heel_deg) e[0] = r;
    if (r.heel_deg > e[1].heel_deg) e[1] = r;
    if (r.pitch_deg < e[2].pitch_deg) e[2] = r;
    if (r.pitch_deg > e[3].pitch_deg) e[3] = r;
  }

  [[nodiscard]] std::vector<AttitudeRow> rows() const {
    std::vector<AttitudeRow> out;
    for (std::size_t b = 0; b < extremes_.size(); ++b) {
      if (!used_[b]) continue;
      auto e = extremes_[b];
      std::sort(e.begin(), e.end(),
                [](const AttitudeRow& x, const AttitudeRow& y) { return x.t_utc_ns < y.t_utc_ns; });
      for (std::size_t i = 0; i < e.size(); ++i)
        if (i == 0 || e[i].t_utc_ns != e[i - 1].t_utc_ns) out.push_back(e[i]);
    }
    return out;
  }

 private:
  std::uint64_t first_ns_;
  double span_;
  std::vector<std::array<AttitudeRow, 4>> extremes_;
  std::vector<bool> used_;
};

/// Column arrays for charts. Beyond max_points, the range is thinned (ChartThinner). A range long
/// enough for whole tier buckets to fill the chart is read from the store's chart tiers (a few
/// thousand rows for a 4-hour session, whatever its rate), a shorter one from the samples; a
/// downsampled count from the tiers includes the whole buckets at the range's ends. Returns the
/// JSON text, with the members of `extra` after the columns. The columns are written straight to
/// text (append_json_number): a 2000-point chart as json arrays cost ~3x the rest of the request.
std::string attitude_columns(Store& store, const std::string& boat_id, std::uint64_t from_ns,
                             std::uint64_t to_ns, std::optional<std::size_t> max_points,
                             const json& extra) {
  std::vector<AttitudeRow> rows;
  std::int64_t count = 0;
  bool downsample = false;
  std::optional<std::vector<TierBucket>> tier;
  if (max_points) {
    // The coarsest tier says how many samples the range holds and over what span.
    auto coarse = store.attitude_tier(boat_id, kTierWidths_s.back(), from_ns, to_ns);
    for (const auto& b : coarse) count += b.n;
    const std::size_t target = *max_points / 4;  // buckets of at most 4 samples
    if (count > static_cast<std::int64_t>(*max_points) && !coarse.empty()) {
      const std::uint64_t span_s =
          (std::min<std::uint64_t>(to_ns,
                                   coarse.back().start_ns + kTierWidths_s.back() * 1000000000ULL) -
           std::max<std::uint64_t>(from_ns, coarse.front().start_ns)) /
          1000000000ULL;
      // The coarsest width that still gives every chart bucket a tier bucket of its own.
      for (auto w = kTierWidths_s.rbegin(); w != kTierWidths_s.rend(); ++w) {
        if (span_s / *w < target) continue;
        tier = *w == kTierWidths_s.back() ? std::move(coarse)
                                         : store.attitude_tier(boat_id, *w, from_ns, to_ns);
        break;
      }
    }
  }
  if (tier) {
    downsample = true;
    std::uint64_t first_ns = UINT64_MAX, last_ns = 0;
    const auto in_range = [&](const AttitudeRow& r) {
      return r.t_utc_ns >= from_ns && r.t_utc_ns <= to_ns;
    };
    for (const auto& b : *tier)
      for (const auto& r : b.extremes)
        if (in_range(r)) {
          first_ns = std::min(first_ns, r.t_utc_ns);
          last_ns = std::max(last_ns, r.t_utc_ns);
        }
    if (first_ns <= last_ns) {
      ChartThinner thin(first_ns, last_ns, *max_points / 4);
      for (const auto& b : *tier)
        for (const auto& r : b.extremes)
          if (in_range(r)) thin.add(r);
      rows = thin.rows();
    }
  } else {
    count = 0;
    std::uint64_t first_ns = 0;
    std::uint64_t last_ns = 0;
    // First pass: count and time span (cheap: the primary key orders by time).
    store.visit_attitude(boat_id, from_ns, to_ns, [&](const AttitudeRow& r) {
      if (count == 0) first_ns = r.t_utc_ns;
      last_ns = r.t_utc_ns;
      ++count;
      if (!max_points || count <= static_cast<std::int64_t>(*max_points)) rows.push_back(r);
      return true;
    });
    downsample = max_points && count > static_cast<std::int64_t>(*max_points);
    if (downsample) {
      ChartThinner thin(first_ns, last_ns, *max_points / 4);
      store.visit_attitude(boat_id, from_ns, to_ns, [&](const AttitudeRow& r) {
        thin.add(r);
        return true;
      });
      rows = thin.rows();
    }
  }
  std::string out = "{\"boat_id\":" + to_json_text(boat_id) +
                    ",\"count\":" + std::to_string(count) +
                    ",\"downsampled\":" + (downsample ? "true" : "false") +
                    ",\"points\":" + std::to_string(rows.size());
  out.reserve(out.size() + rows.size() * 4 * 14 + 256);
  append_number_column(out, "t_s", rows,
                       [](const AttitudeRow& r) { return static_cast<double>(r.t_utc_ns) * 1e-9; });
  append_number_column(out, "heel_deg", rows, [](const AttitudeRow& r) { return r.heel_deg; });
  append_number_column(out, "pitch_deg", rows, [](const AttitudeRow& r) { return r.pitch_deg; });
  append_number_column(out, "heading_deg", rows,
                       [](const AttitudeRow& r) { return r.heading_deg; });
  for (const auto& [key, value] : extra.items())
    out += "," + to_json_text(key) + ":" + to_json_text(value);
  return out + "}";
}

/// Seconds spent in each 5-degree heel band over a session (a gap counts at most 1 s).
json heel_bands(Store& store, const SessionInfo& s) {
  static constexpr std::array<double, 13> kEdges = {-90, -25, -20, -15, -10, -5, 0,
                                                    5,   10,  15,  20,  25,  90};
  std::array<double, kEdges.size() - 1> seconds{};
  std::optional<AttitudeRow> prev;
  const auto add = [&](const AttitudeRow& r, double dt) {
    for (std::size_t i = 0; i + 1 < kEdges.size(); ++i) {
      if (r.heel_deg >= kEdges[i] && (r.heel_deg < kEdges[i + 1] || i + 2 == kEdges.size())) {
        seconds[i] += dt;
        return;
      }
    }
  };
  store.visit_attitude(s.boat_id, s.start_ns, s.end_ns, [&](const AttitudeRow& r) {
    if (prev) add(*prev, std::min(1.0, static_cast<double>(r.t_utc_ns - prev->t_utc_ns) * 1e-9));
    prev = r;
    return true;
  });
  json bands = json::array();
  for (std::size_t i = 0; i + 1 < kEdges.size(); ++i)
    bands.push_back({{"from_deg", kEdges[i]}, {"to_deg", kEdges[i + 1]}, {"seconds", seconds[i]}});
  return bands;
}

/// Export file name; a boat id stored before the shore checked ids may hold anything, so only
/// the id contract's characters pass into the header.
std::string safe_filename(const std::string& boat_id, std::int64_t session_id, Format f) {
  std::string id = boat_id.substr(0, 32);
  for (char& c : id)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-'))
      c = '_';
  return "telltale_" + id + "_session" + std::to_string(session_id) +
         (f == Format::kCsv ? ".csv" : ".json");
}

}  // namespace

void register_rest_routes(httplib::Server& server, ShoreContext& ctx) {
  auto snapshot = std::make_shared<BoatsSnapshot>();
  server.Get("/api/v1/boats", [&ctx, snapshot](const httplib::Request& req,
                                               httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {});
    if (p.role == Role::kAthlete) {  // an athlete sees their own boat only, always fresh
      std::vector<BoatView> own;
      if (auto b = ctx.fleet.boat(p.boat_id)) own.push_back(std::move(*b));
      res.set_content(boats_json(own), "application/json");
      return;
    }
    res.set_content(*snapshot->get(ctx.fleet), "application/json");
  });

  server.Get(R"(/api/v1/boats/([^/]+))",
             [&ctx](const httplib::Request& req, httplib::Response& res) {
               const Principal p = who(ctx, req);
               allow_params(req, {});
               const std::string id = path_id(req, "boat");
               require_boat(p, id);
               const auto view = ctx.fleet.boat(id);
               if (!view) throw HttpError(404, "unknown boat '" + id + "'");
               res.set_content(boat_json(*view), "application/json");
             });

  server.Get(R"(/api/v1/boats/([^/]+)/attitude)", [&ctx](const httplib::Request& req,
                                                         httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"from", "to", "max_points", "format"});
    const std::string id = path_id(req, "boat");
    require_boat(p, id);
    const TimeRange range = parse_range(param(req, "from"), param(req, "to"));
    const Format format = format_of(req);
    const auto max_points = max_points_of(req);
    if (!ctx.fleet.boat(id) && !ctx.store.knows_boat(id))
      throw HttpError(404, "unknown boat '" + id + "'");
    if (format == Format::kCsv) {
      if (max_points) throw HttpError(400, "max_points applies to JSON only");
      stream_rows(res, ctx.store, id, range.from_ns, range.to_ns, format, json::object(), "");
      return;
    }
    const json extra = {
        {"from", range.from_ns ? json(iso8601(range.from_ns)) : json(nullptr)},
        {"to", range.to_ns != UINT64_MAX ? json(iso8601(range.to_ns)) : json(nullptr)}};
    res.set_content(attitude_columns(ctx.store, id, range.from_ns, range.to_ns, max_points, extra),
                    "application/json");
  });

  server.Get("/api/v1/athletes", [&ctx](const httplib::Request& req, httplib::Response& res) {
    const Principal p = who(ctx, req);
    if (p.role == Role::kAthlete) throw HttpError(403, "an athlete sees only their own boat");
    allow_params(req, {});
    json arr = json::array();
    for (const auto& a : ctx.fleet.athletes()) arr.push_back(athlete_object(a));
    res.set_content(to_json_text(arr), "application/json");
  });

  server.Get(R"(/api/v1/athletes/([^/]+)/track)", [&ctx](const httplib::Request& req,
                                                         httplib::Response& res) {
    const Principal p = who(ctx, req);
    if (p.role == Role::kAthlete) throw HttpError(403, "an athlete sees only their own boat");
    allow_params(req, {"from", "to"});
    const std::string id = path_id(req, "athlete");
    const TimeRange range = parse_range(param(req, "from"), param(req, "to"));
    if (!ctx.fleet.athlete(id)) {
      if (ctx.store.wearable_track(id, 0, UINT64_MAX, 1).empty())
        throw HttpError(404, "unknown athlete '" + id + "'");
    }
    json t = json::array(), x = json::array(), y = json::array(), steps = json::array();
    for (const auto& w : ctx.store.wearable_track(id, range.from_ns, range.to_ns, 200000)) {
      t.push_back(static_cast<double>(w.t_utc_ns) * 1e-9);
      x.push_back(finite_or_null(w.x_m));
      y.push_back(finite_or_null(w.y_m));
      steps.push_back(w.steps);
    }
    res.set_content(to_json_text(json{
                        {"athlete_id", id}, {"t_s", t}, {"x_m", x}, {"y_m", y}, {"steps", steps}}),
                    "application/json");
  });

  server.Get("/api/v1/sessions", [&ctx](const httplib::Request& req, httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"boat", "from", "to"});
    const std::optional<std::string> boat = boat_filter(req, p);
    const TimeRange range = parse_range(param(req, "from"), param(req, "to"));
    json arr = json::array();
    for (const auto& s : ctx.store.sessions(boat, range.from_ns, range.to_ns))
      arr.push_back(session_object(s));
    res.set_content(to_json_text(arr), "application/json");
  });

  const auto session_or_404 = [&ctx](const httplib::Request& req, const Principal& p) {
    const std::int64_t id = path_number(req, "session");
    auto s = ctx.store.session(id);
    if (!s) throw HttpError(404, "unknown session " + std::to_string(id));
    require_boat(p, s->boat_id);
    return *s;
  };

  server.Get(R"(/api/v1/sessions/([^/]+))",
             [&ctx, session_or_404](const httplib::Request& req, httplib::Response& res) {
               const Principal p = who(ctx, req);
               allow_params(req, {});
               const SessionInfo s = session_or_404(req, p);
               json j = session_object(s);
               j["heel_bands"] = heel_bands(ctx.store, s);
               const FixStats g = ctx.store.fix_stats(s.boat_id, s.start_ns, s.end_ns);
               j["gnss"] = {{"fixes", g.fixes},
                            {"distance_m", g.fixes ? json(g.distance_m) : json(nullptr)},
                            {"time_with_fix_s", g.time_with_fix_s},
                            {"sog_mean_m_s", finite_or_null(g.sog_mean_m_s)},
                            {"sog_max_m_s", finite_or_null(g.sog_max_m_s)}};
               EventFilter f;
               f.boat_id = s.boat_id;
               f.from_ns = s.start_ns;
               f.to_ns = s.end_ns;
               f.limit = 10000;
               json events = json::array();
               for (const auto& e : ctx.store.events(f)) events.push_back(event_object(e));
               j["alarm_events"] = std::move(events);
               res.set_content(to_json_text(j), "application/json");
             });

  server.Get(R"(/api/v1/sessions/([^/]+)/attitude)",
             [&ctx, session_or_404](const httplib::Request& req, httplib::Response& res) {
               const Principal p = who(ctx, req);
               allow_params(req, {"max_points"});
               const SessionInfo s = session_or_404(req, p);
               res.set_content(attitude_columns(ctx.store, s.boat_id, s.start_ns, s.end_ns,
                                                max_points_of(req), {{"session_id", s.id}}),
                               "application/json");
             });

  server.Get(R"(/api/v1/sessions/([^/]+)/export)",
             [&ctx, session_or_404](const httplib::Request& req, httplib::Response& res) {
               const Principal p = who(ctx, req);
               allow_params(req, {"format"});
               if (!param(req, "format")) throw HttpError(400, "format is required: csv or json");
               const Format format = format_of(req);
               const SessionInfo s = session_or_404(req, p);
               stream_rows(res, ctx.store, s.boat_id, s.start_ns, s.end_ns, format,
                           {{"session", session_object(s)}},
                           safe_filename(s.boat_id, s.id, format));
             });

  server.Get("/api/v1/alarms/rules", [&ctx](const httplib::Request& req, httplib::Response& res) {
    (void)who(ctx, req);
    allow_params(req, {});
    json arr = json::array();
    for (const auto& r : ctx.alarms.rules()) arr.push_back(rule_object(r));
    res.set_content(to_json_text(arr), "application/json");
  });

  server.Put("/api/v1/alarms/rules", [&ctx](const httplib::Request& req, httplib::Response& res) {
    require_coach(who(ctx, req));
    allow_params(req, {});
    const std::string type = req.get_header_value("Content-Type");
    if (type.rfind("application/json", 0) != 0)
      throw HttpError(415, "body must be application/json");
    ctx.alarms.put_rules(rules_from_body(req.body), utc_now_ns());
    json arr = json::array();
    for (const auto& r : ctx.alarms.rules()) arr.push_back(rule_object(r));
    res.set_content(to_json_text(arr), "application/json");
  });

  server.Get("/api/v1/alarms/events", [&ctx](const httplib::Request& req, httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"boat", "from", "to", "active", "limit"});
    EventFilter f;
    f.boat_id = boat_filter(req, p);
    const TimeRange range = parse_range(param(req, "from"), param(req, "to"));
    f.from_ns = range.from_ns;
    f.to_ns = range.to_ns;
    if (const std::string* a = param(req, "active")) {
      if (*a != "true" && *a != "false") throw HttpError(400, "active must be true or false");
      f.active_only = *a == "true";
    }
    if (const std::string* l = param(req, "limit")) {
      const auto n = parse_int(*l, 1, 10000);
      if (!n) throw HttpError(400, "limit must be an integer in 1..10000");
      f.limit = static_cast<std::size_t>(*n);
    }
    json arr = json::array();
    for (const auto& e : ctx.store.events(f)) arr.push_back(event_object(e));
    res.set_content(to_json_text(arr), "application/json");
  });

  const auto event_action = [&ctx](bool acknowledge) {
    return [&ctx, acknowledge](const httplib::Request& req, httplib::Response& res) {
      require_coach(who(ctx, req));
      allow_params(req, {});
      const auto id = parse_int(req.matches[1], 1, INT64_MAX);
      if (!id) throw HttpError(400, "event id must be a positive integer");
      const auto ev_id = static_cast<std::uint64_t>(*id);
      const auto e = acknowledge ? ctx.alarms.acknowledge(ev_id, utc_now_ns())
                                 : ctx.alarms.silence(ev_id, utc_now_ns());
      if (!e) {
        if (ctx.store.event(ev_id)) throw HttpError(409, "event already cleared");
        throw HttpError(404, "unknown event " + std::to_string(ev_id));
      }
      res.set_content(to_json_text(event_object(*e)), "application/json");
    };
  };
  server.Post(R"(/api/v1/alarms/events/([^/]+)/ack)", event_action(true));
  server.Post(R"(/api/v1/alarms/events/([^/]+)/silence)", event_action(false));
}

}  // namespace telltale::shore
