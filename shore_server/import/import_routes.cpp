#include "import_routes.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "json_views.hpp"
#include "query.hpp"
#include "route_helpers.hpp"
#include "detect.hpp"
#include "time_zone.hpp"
#include "vtk.hpp"

namespace telltale::shore {
namespace {

using nlohmann::json;

double angle_param(const httplib::Request& req, const char* name, double limit) {
  const std::string* v = param(req, name);
  if (!v) return 0.0;
  const auto d = import::parse_decimal(*v);
  if (!d || std::fabs(*d) > limit)
    throw HttpError(400, std::string(name) + " must be a number of degrees within ±" +
                             std::to_string(static_cast<int>(limit)));
  return *d;
}

}  // namespace

json import_json(const import::ImportRecord& r) {
  json j = {{"id", r.id},
            {"boat_id", r.boat_id},
            {"state", r.state},
            {"file_name", r.file_name},
            {"format", r.format.empty() ? json(nullptr) : json(r.format)},
            {"device", r.device.empty() ? json(nullptr) : json(r.device)},
            {"sha256", r.sha256.empty() ? json(nullptr) : json(r.sha256)},
            {"bytes", r.bytes},
            {"bytes_read", r.bytes_read},
            {"sessions", r.sessions},
            {"points", r.points},
            {"samples_added", r.samples_added},
            {"fixes_added", r.fixes_added},
            {"wind_added", r.wind_added},
            {"events", r.events},
            {"skipped", r.skipped},
            {"start", r.start_ns ? json(iso8601(r.start_ns)) : json(nullptr)},
            {"end", r.end_ns ? json(iso8601(r.end_ns)) : json(nullptr)},
            {"error", r.error.empty() ? json(nullptr) : json(r.error)},
            {"partial", r.partial.empty() ? json(nullptr) : json(r.partial)},
            {"duplicate_of", r.duplicate_of ? json(r.duplicate_of) : json(nullptr)}};
  return j;
}

void register_import_routes(httplib::Server& server, ShoreContext& ctx,
                            import::ImportService& imports, std::size_t max_import_bytes) {
  server.Post("/api/v1/imports", [&ctx, &imports, max_import_bytes](
                                     const httplib::Request& req, httplib::Response& res,
                                     const httplib::ContentReader& content) {
    const Principal p = who(ctx, req);
    if (p.role == Role::kAthlete) throw HttpError(403, "only a coach or an analyst may import");
    allow_params(req, {"boat", "format", "tz", "heel_offset", "pitch_offset", "declination", "date",
                       "name"});
    import::ImportRequest r;
    const std::string* boat = param(req, "boat");
    if (boat && !valid_id(*boat)) throw HttpError(400, "boat id must be 1-32 of [A-Za-z0-9_-]");
    if (boat) r.boat_id = *boat;
    if (const std::string* f = param(req, "format")) {
      r.format = import::parse_format(*f);
      if (!r.format) throw HttpError(400, "format must be one of vakaros_csv, vkx, vtk, nmea, gpx");
    }
    if (const std::string* tz = param(req, "tz")) {
      r.options.utc_offset_s = import::parse_utc_offset(*tz);
      if (!r.options.utc_offset_s) {
        auto zone = import::TimeZone::load(*tz);
        if (!zone)
          throw HttpError(400,
                          "tz must be a time zone such as Europe/Madrid or a UTC offset such as "
                          "+01:00, -0700 or UTC");
        r.options.local_offset_s = [z = std::move(*zone)](std::int64_t local_s) {
          return z.offset_at_local(local_s);
        };
      }
    }
    if (const std::string* d = param(req, "date")) {
      bool zone = false;
      const auto t = import::parse_iso_time(*d + "T00:00:00Z", std::nullopt, &zone);
      if (d->size() != 10 || !t) throw HttpError(400, "date must be YYYY-MM-DD");
      r.options.date_days = static_cast<std::int64_t>(*t / 86'400'000'000'000ULL);
    }
    r.options.heel_offset_deg = angle_param(req, "heel_offset", 45.0);
    r.options.pitch_offset_deg = angle_param(req, "pitch_offset", 45.0);
    if (param(req, "declination")) r.options.declination_deg = angle_param(req, "declination", 90.0);
    r.file_name = "upload";
    if (const std::string* n = param(req, "name")) {
      if (n->empty() || n->size() > 200) throw HttpError(400, "name must be 1-200 characters");
      r.file_name = *n;
    }
    if (!req.has_header("Content-Length"))
      throw HttpError(411, "send the file with a Content-Length");
    // The body goes to a spool file as it arrives: an upload is never held in memory.
    r.path = imports.spool_path().string();
    std::uint64_t bytes = 0;
    {
      std::ofstream out(r.path, std::ios::binary);
      if (!out) throw HttpError(500, "cannot write the spool file");
      const bool ok = content([&](const char* data, std::size_t n) {
        bytes += n;
        if (bytes > max_import_bytes) return false;
        out.write(data, static_cast<std::streamsize>(n));
        return static_cast<bool>(out);
      });
      if (!ok || !out) {
        out.close();
        std::remove(r.path.c_str());
        throw HttpError(bytes > max_import_bytes ? 413 : 400,
                        bytes > max_import_bytes ? "file larger than the shore's import limit"
                                                 : "the upload was cut or could not be stored");
      }
    }
    if (bytes == 0) {
      std::remove(r.path.c_str());
      throw HttpError(400, "empty body: send the file as the request body");
    }
    if (r.boat_id.empty()) {
      // No boat given: the device's serial where the file names one (Velocitek VTK).
      std::string head(import::kDetectBytes, '\0');
      std::ifstream in(r.path, std::ios::binary);
      in.read(head.data(), static_cast<std::streamsize>(head.size()));
      head.resize(static_cast<std::size_t>(in.gcount()));
      const auto format = r.format ? r.format : import::detect_format(head);
      const auto serial = format == import::Format::kVtk ? import::vtk_serial_number(head)
                                                          : std::nullopt;
      if (!serial) {
        std::remove(r.path.c_str());
        throw HttpError(400,
                        "boat is required: the boat the file belongs to (this file names no "
                        "device serial to take it from)");
      }
      r.boat_id = "velocitek-" + std::to_string(*serial);
    }
    const std::int64_t id = imports.submit(std::move(r), bytes);
    res.status = 202;
    res.set_header("Location", "/api/v1/imports/" + std::to_string(id));
    res.set_content(to_json_text(json{{"id", id}, {"state", "running"}}), "application/json");
  });

  server.Get("/api/v1/imports", [&ctx, &imports](const httplib::Request& req,
                                                 httplib::Response& res) {
    const Principal p = who(ctx, req);
    allow_params(req, {"boat", "session", "limit"});
    const std::optional<std::string> boat = boat_filter(req, p);
    std::optional<std::int64_t> session;
    if (const std::string* s = param(req, "session")) {
      session = parse_int(*s, 1, INT64_MAX);
      if (!session) throw HttpError(400, "session must be a positive integer");
    }
    std::int64_t limit = 100;
    if (const std::string* l = param(req, "limit")) {
      const auto n = parse_int(*l, 1, 1000);
      if (!n) throw HttpError(400, "limit must be an integer in 1..1000");
      limit = *n;
    }
    json out = json::array();
    for (const auto& r : imports.list(boat, session, static_cast<std::size_t>(limit)))
      out.push_back(import_json(r));
    res.set_content(to_json_text(out), "application/json");
  });

  server.Get(R"(/api/v1/imports/([^/]+))",
             [&ctx, &imports](const httplib::Request& req, httplib::Response& res) {
               const Principal p = who(ctx, req);
               allow_params(req, {});
               const std::int64_t id = path_number(req, "import");
               const auto r = imports.status(id);
               if (!r) throw HttpError(404, "no import " + std::to_string(id));
               require_boat(p, r->boat_id);
               res.set_content(to_json_text(import_json(*r)), "application/json");
             });
}

}  // namespace telltale::shore
