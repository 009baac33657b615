#include "http_api.hpp"

#include <httplib.h>

#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>

#include "openapi_json.hpp"

namespace telltale::shore {

using nlohmann::json;

std::string iso8601(std::uint64_t t_utc_ns) {
  const auto secs = static_cast<std::time_t>(t_utc_ns / 1000000000ULL);
  const auto ms = static_cast<unsigned>((t_utc_ns / 1000000ULL) % 1000ULL);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03uZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
  return buf;
}

namespace {

json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json boat_object(const BoatView& v) {
  const AttitudeSample& s = v.last;
  json j = {
      {"id", s.boat_id},
      {"kind", v.status ? v.status->kind : std::string("boat")},
      {"seq", s.seq},
      {"t_utc_ns", s.t_utc_ns},
      {"last_sample_time", iso8601(s.t_utc_ns)},
      {"heel_deg", finite_or_null(s.heel_deg)},
      {"pitch_deg", finite_or_null(s.pitch_deg)},
      {"heading_deg", finite_or_null(s.heading_deg)},
      {"heel_rate_deg_s", finite_or_null(s.heel_rate_deg_s)},
      {"pitch_rate_deg_s", finite_or_null(s.pitch_rate_deg_s)},
      {"yaw_rate_deg_s", finite_or_null(s.yaw_rate_deg_s)},
      {"accel_weight", finite_or_null(static_cast<double>(s.accel_weight))},
      {"quality", finite_or_null(static_cast<double>(s.quality))},
      {"leds",
       {{"left", s.leds[0]}, {"right", s.leds[1]}, {"up", s.leds[2]}, {"down", s.leds[3]},
        {"count", s.led_count}}},
      {"alarm_state", v.alarm_state},
      {"stale", v.stale},
      {"samples_received", v.samples_received},
  };
  if (v.status) {
    j["status"] = {{"software_version", v.status->software_version},
                   {"uptime_s", v.status->uptime_s},
                   {"sensor_health", v.status->sensor_health},
                   {"health_text", v.status->health_text}};
  }
  return j;
}

void json_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(json{{"error", message}}.dump(), "application/json");
}

bool is_open_path(const std::string& path) {
  // Only the health check, the API description, login and the static dashboard are open.
  if (path == "/healthz" || path == "/api/v1/openapi.json" || path == "/api/v1/login") return true;
  return path.rfind("/api/", 0) != 0;
}

}  // namespace

std::string boat_json(const BoatView& view) { return boat_object(view).dump(); }

struct HttpApi::Impl {
  HttpConfig config;
  FleetModel& fleet;
  LiveHub& hub;
  TokenStore& tokens;
  SampleStore& store;
  httplib::Server server;

  Impl(HttpConfig c, FleetModel& f, LiveHub& h, TokenStore& t, SampleStore& s)
      : config(std::move(c)), fleet(f), hub(h), tokens(t), store(s) {}

  std::optional<Principal> principal(const httplib::Request& req) const {
    return tokens.find(token_from_headers(req.get_header_value("Authorization"),
                                          req.get_header_value("Cookie")));
  }

  void configure() {
    // Deliberate settings: the library's defaults (5 keep-alive requests per connection, no
    // TCP_NODELAY, a pool of max(8, cores-1) threads) starve under a handful of streams.
    server.set_tcp_nodelay(true);
    server.set_keep_alive_max_count(10000);
    server.set_keep_alive_timeout(30);
    server.set_read_timeout(5, 0);
    server.set_write_timeout(5, 0);
    server.set_payload_max_length(config.max_body_bytes);
    const std::size_t workers = config.max_stream_clients + config.rest_threads;
    server.new_task_queue = [workers] { return new httplib::ThreadPool(workers); };

    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      if (is_open_path(req.path)) return httplib::Server::HandlerResponse::Unhandled;
      if (!principal(req)) {
        res.set_header("WWW-Authenticate", "Bearer");
        json_error(res, 401, "missing or invalid token");
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
    server.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
      if (!res.body.empty()) return;
      if (res.status == 404) {
        json_error(res, 404, "no such resource: " + req.path);
      } else if (res.status == 413) {
        json_error(res, 413, "request body too large");
      } else {
        json_error(res, res.status, "request failed");
      }
    });
    server.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
          std::string what = "internal error";
          try {
            std::rethrow_exception(ep);
          } catch (const std::exception& e) {
            what = e.what();
          } catch (...) {
          }
          json_error(res, 500, what);
        });

    server.Get("/healthz", [this](const httplib::Request&, httplib::Response& res) {
      const std::string store_error = store.last_error();
      json j = {{"status", store_error.empty() ? "ok" : "degraded"},
                {"boats", fleet.boats().size()},
                {"stream_clients", hub.clients()},
                {"samples_committed", store.committed()}};
      if (!store_error.empty()) j["store_error"] = store_error;
      res.set_content(j.dump(), "application/json");
    });
    server.Get("/api/v1/openapi.json", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(kOpenApiJson, "application/json");
    });
    server.Post("/api/v1/login", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string token =
          token_from_headers(req.get_header_value("Authorization"), std::string());
      const auto who = tokens.find(token);
      if (!who) {
        json_error(res, 401, "missing or invalid token");
        return;
      }
      // The dashboard's EventSource cannot send headers: the cookie carries the token.
      res.set_header("Set-Cookie", "telltale_token=" + token +
                                       "; Path=/; HttpOnly; SameSite=Strict; Max-Age=86400");
      res.set_content(json{{"role", role_name(who->role)}}.dump(), "application/json");
    });
    server.Post("/api/v1/logout", [](const httplib::Request&, httplib::Response& res) {
      res.set_header("Set-Cookie", "telltale_token=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0");
      res.status = 204;
    });
    server.Get("/api/v1/boats", [this](const httplib::Request&, httplib::Response& res) {
      json arr = json::array();
      for (const auto& b : fleet.boats()) arr.push_back(boat_object(b));
      res.set_content(arr.dump(), "application/json");
    });
    server.Get("/api/v1/stream", [this](const httplib::Request&, httplib::Response& res) {
      auto client = hub.connect();
      if (!client) {
        json_error(res, 503, "too many live streams");
        return;
      }
      res.set_header("Cache-Control", "no-store");
      // The current fleet first, so a new dashboard draws at once; then live updates.
      std::string snapshot = "retry: 2000\n\n";
      for (const auto& b : fleet.boats()) snapshot += "event: sample\ndata: " + boat_json(b) + "\n\n";
      res.set_chunked_content_provider(
          "text/event-stream",
          [this, client, pending = std::move(snapshot)](std::size_t,
                                                         httplib::DataSink& sink) mutable {
            bool closed = false;
            std::string out = std::move(pending);
            pending.clear();
            if (out.empty()) out = hub.wait(*client, std::chrono::seconds(15), closed);
            if (closed) {
              sink.done();
              return false;
            }
            if (out.empty()) out = ": keep-alive\n\n";
            return sink.write(out.data(), out.size());
          },
          [this, client](bool) { hub.disconnect(client); });
    });
    if (!config.web_dir.empty() && !server.set_mount_point("/", config.web_dir))
      throw std::runtime_error("web directory not found: " + config.web_dir);
  }
};

HttpApi::HttpApi(HttpConfig config, FleetModel& fleet, LiveHub& hub, TokenStore& tokens,
                 SampleStore& store)
    : impl_(std::make_unique<Impl>(std::move(config), fleet, hub, tokens, store)) {
  impl_->configure();
}

HttpApi::~HttpApi() = default;

int HttpApi::bind() {
  int port = impl_->config.port;
  if (port == 0) {
    port = impl_->server.bind_to_any_port(impl_->config.bind_address);
  } else if (!impl_->server.bind_to_port(impl_->config.bind_address, port)) {
    port = -1;
  }
  if (port <= 0)
    throw std::runtime_error("cannot listen on " + impl_->config.bind_address + ":" +
                             std::to_string(impl_->config.port));
  return port;
}

void HttpApi::serve() { impl_->server.listen_after_bind(); }

void HttpApi::stop() { impl_->server.stop(); }

}  // namespace telltale::shore
