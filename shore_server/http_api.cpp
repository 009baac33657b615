#include "http_api.hpp"
#include "track_routes.hpp"
#include "manoeuvre_routes.hpp"
#include "import_routes.hpp"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>
#include <unistd.h>

#include "http_guard.hpp"
#include "json_views.hpp"
#include "openapi_json.hpp"
#include "query.hpp"

namespace telltale::shore {

using nlohmann::json;

namespace {

void json_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(to_json_text(json{{"error", message}}), "application/json");
}

/// More than this many query parameters is a client error (no route takes more than five).
constexpr std::size_t kMaxQueryParams = 32;

bool is_open_path(const std::string& path) {
  // Only the health check, the API description, login and the static dashboard are open.
  if (path == "/healthz" || path == "/api/v1/openapi.json" || path == "/api/v1/login") return true;
  return path.rfind("/api/", 0) != 0;
}

}  // namespace

Principal authenticate(const TokenStore& tokens, const std::string& authorization,
                       const std::string& cookie) {
  auto who = tokens.find(token_from_headers(authorization, cookie));
  if (!who) throw HttpError(401, "missing or invalid token");
  return *who;
}

struct HttpApi::Impl {
  HttpConfig config;
  ShoreContext ctx;
  GuardedServer server;
  std::atomic<bool> stop_requested{false};
  std::atomic<bool> served{false};  ///< serve() has returned
  std::unique_ptr<import::ImportService> imports;

  Impl(HttpConfig c, ShoreContext context)
      : config(std::move(c)), ctx(context), server(guard_limits(config)) {}

  static GuardLimits guard_limits(const HttpConfig& c) {
    GuardLimits l;
    // Every stream and REST worker, plus headroom that idle or slow connections may take
    // before the guard tightens its timeouts (http_guard.hpp).
    l.workers = c.max_stream_clients + c.rest_threads + c.spare_threads;
    l.spare_workers = std::max<std::size_t>(4, c.spare_threads / 2);
    l.idle_timeout = std::chrono::seconds(c.keep_alive_s);
    return l;
  }

  std::optional<Principal> principal(const httplib::Request& req) const {
    return ctx.tokens.find(
        token_from_headers(req.get_header_value("Authorization"), req.get_header_value("Cookie")));
  }

  void configure() {
    // Deliberate settings: the library's defaults (5 keep-alive requests per connection, no
    // TCP_NODELAY, a pool of max(8, cores-1) threads) starve under a handful of streams.
    server.set_tcp_nodelay(true);
    // The pool, the keep-alive idle limit and the request deadlines are GuardedServer's.
    server.set_keep_alive_max_count(10000);
    server.set_read_timeout(5, 0);
    server.set_write_timeout(5, 0);
    server.set_payload_max_length(std::max(config.max_body_bytes, config.max_import_bytes));

    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      // Bodies: a length we accept, said up front; nothing else is read. Refused at once, and the
      // connection closed, so an unread body is never parsed as the next request.
      if (req.has_header("Transfer-Encoding")) {
        GuardedServer::close_after_response();
        json_error(res, 411,
                   "chunked request bodies are not accepted: send a Content-Length (at most " +
                       std::to_string(config.max_body_bytes) + " bytes)");
        return httplib::Server::HandlerResponse::Handled;
      }
      if (req.has_header("Content-Length")) {
        const auto n = parse_int(req.get_header_value("Content-Length"), 0, INT64_MAX);
        if (!n) {
          GuardedServer::close_after_response();
          json_error(res, 400, "Content-Length must be a whole number of bytes");
          return httplib::Server::HandlerResponse::Handled;
        }
        // An imported log may be larger than any other body (it is spooled to disk).
        const std::size_t limit = req.method == "POST" && req.path == "/api/v1/imports"
                                      ? config.max_import_bytes
                                      : config.max_body_bytes;
        if (static_cast<std::uint64_t>(*n) > limit) {
          GuardedServer::close_after_response();
          json_error(res, 413,
                     "request body too large (at most " + std::to_string(limit) + " bytes)");
          return httplib::Server::HandlerResponse::Handled;
        }
      }
      if (req.params.size() > kMaxQueryParams) {
        json_error(res, 400,
                   "too many query parameters (at most " + std::to_string(kMaxQueryParams) + ")");
        return httplib::Server::HandlerResponse::Handled;
      }
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
      if (res.status == 400 && GuardedServer::request_too_large()) {
        json_error(res, 431, "request line and headers too large");
      } else if (res.status == 404) {
        json_error(res, 404, "no such resource: " + req.path);
      } else if (res.status == 413) {
        json_error(res, 413, "request body too large");
      } else if (res.status == 414) {
        json_error(res, 414,
                   "request line longer than 8192 bytes (too many or too long query "
                   "parameters)");
      } else {
        json_error(res, res.status,
                   res.status == 400 ? "malformed request (a POST or PUT needs a Content-Length)"
                                     : "request failed");
      }
    });
    // The one exception handler: HttpError carries its 4xx; anything else is a 500.
    server.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
          try {
            std::rethrow_exception(ep);
          } catch (const HttpError& e) {
            if (e.status() == 401) res.set_header("WWW-Authenticate", "Bearer");
            json_error(res, e.status(), e.what());
          } catch (const std::exception& e) {
            json_error(res, 500, e.what());
          } catch (...) {
            json_error(res, 500, "internal error");
          }
        });

    server.Get("/healthz", [this](const httplib::Request&, httplib::Response& res) {
      const std::string store_error = ctx.store.last_error();
      const auto boats = ctx.fleet.boats();
      json j = {{"status", store_error.empty() ? "ok" : "degraded"},
                {"boats", boats.size()},
                {"stream_clients", ctx.hub.clients()},
                {"samples_committed", ctx.store.committed()},
                {"fixes_committed", ctx.store.fixes_committed()}};
      if (!store_error.empty()) j["store_error"] = store_error;
      // The writer: a failing disk shows as a backlog, refused samples and the next retry.
      const StoreHealth sh = ctx.store.health();
      j["store"] = {{"failing", sh.failing},
                    {"backlog", sh.backlog},
                    {"dropped", sh.dropped},
                    {"failed_commits", sh.failed_commits},
                    {"retry_in_s", sh.retry_in_s},
                    {"wearable_backlog", sh.wearable_backlog},
                    {"fix_backlog", sh.fix_backlog},
                    {"wearable_dropped", sh.wearable_dropped},
                    {"fixes_dropped", sh.fixes_dropped},
                    {"wind_backlog", sh.wind_backlog},
                    {"wind_dropped", sh.wind_dropped}};
      if (sh.failing || sh.dropped > 0 || sh.wearable_dropped > 0 || sh.fixes_dropped > 0 ||
          sh.wind_dropped > 0)
        j["status"] = "degraded";
      // What the boats' cards show as badges, by problem: {"log_failing": ["b1"], ...}.
      json problems = json::object();
      for (const auto& b : boats) {
        for (const auto& p : boat_problems(b))
          problems[p["code"].get<std::string>()].push_back(b.last.boat_id);
      }
      j["boat_problems"] = problems;
      // Two nodes sailing with one boat id: the store records the later one apart.
      json duplicates = json::array();
      for (const auto& d : ctx.store.duplicate_ids())
        duplicates.push_back({{"boat_id", d.boat_id}, {"runs", {d.boot_a, d.boot_b}}});
      if (!duplicates.empty()) {
        j["duplicate_boat_ids"] = duplicates;
        j["status"] = "degraded";
      }
      j["http"] = {{"busy_connections", server.busy()},
                   {"workers", server.workers()},
                   {"cut_requests", server.cut_requests()},
                   {"cut_idle", server.cut_idle()}};
      if (ctx.ingest) {
        j["samples_rejected"] = ctx.ingest->rejected_total();
        j["ingest"] = ctx.ingest->to_json();
      }
      res.set_content(to_json_text(j), "application/json");
    });
    server.Get("/api/v1/openapi.json", [](const httplib::Request&, httplib::Response& res) {
      res.set_content(kOpenApiJson, "application/json");
    });
    server.Post("/api/v1/login", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string token =
          token_from_headers(req.get_header_value("Authorization"), std::string());
      const auto who = ctx.tokens.find(token);
      if (!who) {
        json_error(res, 401, "missing or invalid token");
        return;
      }
      // The dashboard's EventSource cannot send headers: the cookie carries the token.
      res.set_header("Set-Cookie", "telltale_token=" + token +
                                       "; Path=/; HttpOnly; SameSite=Strict; Max-Age=86400");
      res.set_content(to_json_text(json{{"role", role_name(who->role)}}), "application/json");
    });
    server.Get("/api/v1/me", [this](const httplib::Request& req, httplib::Response& res) {
      const Principal who = authenticate(ctx.tokens, req.get_header_value("Authorization"),
                                         req.get_header_value("Cookie"));
      res.set_content(
          to_json_text(json{{"role", role_name(who.role)},
                            {"boat_id", who.boat_id.empty() ? json(nullptr) : json(who.boat_id)}}),
          "application/json");
    });
    server.Post("/api/v1/logout", [](const httplib::Request&, httplib::Response& res) {
      res.set_header("Set-Cookie", "telltale_token=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0");
      res.status = 204;
    });
    server.Get("/api/v1/stream", [this](const httplib::Request& req, httplib::Response& res) {
      const Principal who = authenticate(ctx.tokens, req.get_header_value("Authorization"),
                                         req.get_header_value("Cookie"));
      std::optional<std::string> only;
      if (who.role == Role::kAthlete) only = who.boat_id;
      auto client = ctx.hub.connect(only);
      if (!client) {
        json_error(res, 503, "too many live streams");
        return;
      }
      res.set_header("Cache-Control", "no-store");
      // A dashboard that stops reading must fill its buffers in seconds, so that the write
      // timeout frees its slot, not in the minutes a kernel-grown buffer of megabytes takes.
      GuardedServer::cap_send_buffer(static_cast<int>(config.stream_send_buffer_bytes));
      // The current fleet first, so a new dashboard draws at once; then live updates.
      std::string snapshot = "retry: 2000\n\n";
      for (const auto& b : ctx.fleet.boats()) {
        if (!only || *only == b.last.boat_id)
          snapshot += "event: sample\ndata: " + boat_json(b) + "\n\n";
      }
      res.set_chunked_content_provider(
          "text/event-stream",
          [this, client, pending = std::move(snapshot),
           buffer = config.stream_send_buffer_bytes](std::size_t,
                                                     httplib::DataSink& sink) mutable {
            bool closed = false;
            std::string out = std::move(pending);
            pending.clear();
            if (out.empty()) out = ctx.hub.wait(*client, std::chrono::seconds(15), closed);
            if (closed) {
              sink.done();
              return false;
            }
            if (out.empty()) out = ": keep-alive\n\n";
            // The send buffer grows to hold the biggest batch (up to kMaxStreamSendBuffer): a
            // batch bigger than the buffer went out in buffer-sized turns, each waiting for the
            // client to read (1000 boats: ~700 KB a batch through 32 KB; boat -> dashboard p50
            // 235 ms, 31 ms with the buffer grown, deploy/bench_fleet.sh 1000 60 1). A client
            // that stops reading still fills it within one batch; the write timeout frees its
            // slot.
            if (out.size() > buffer && buffer < kMaxStreamSendBuffer) {
              buffer = std::min(out.size(), kMaxStreamSendBuffer);
              GuardedServer::cap_send_buffer(static_cast<int>(buffer));
            }
            return sink.write(out.data(), out.size());
          },
          [this, client](bool) { ctx.hub.disconnect(client); });
    });
    register_rest_routes(server, ctx);
    register_track_routes(server, ctx);
    register_manoeuvre_routes(server, ctx);
    const std::filesystem::path spool =
        config.import_spool_dir.empty()
            ? std::filesystem::temp_directory_path() /
                  ("telltale-imports-" + std::to_string(::getpid()))
            : std::filesystem::path(config.import_spool_dir);
    imports = std::make_unique<import::ImportService>(
        ctx.store, spool, [this](const import::ImportRecord& r) {
          ctx.hub.publish_event("import", to_json_text(import_json(r)), r.boat_id);
        });
    register_import_routes(server, ctx, *imports, config.max_import_bytes);
    if (!config.web_dir.empty() && !server.set_mount_point("/", config.web_dir))
      throw std::runtime_error("web directory not found: " + config.web_dir);
  }
};

HttpApi::HttpApi(HttpConfig config, ShoreContext context)
    : impl_(std::make_unique<Impl>(std::move(config), context)) {
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

void HttpApi::serve() {
  if (!impl_->stop_requested.load()) impl_->server.listen_after_bind();
  impl_->served.store(true);
}

void HttpApi::stop() {
  impl_->stop_requested.store(true);
  // A SIGTERM right after start-up can come before the listen loop runs; stop it once it does.
  while (!impl_->served.load()) {
    if (impl_->server.is_running()) impl_->server.stop();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace telltale::shore
