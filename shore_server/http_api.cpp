#include "http_api.hpp"

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>
#include <thread>

#include "json_views.hpp"
#include "openapi_json.hpp"
#include "query.hpp"

namespace telltale::shore {

using nlohmann::json;

namespace {

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

Principal authenticate(const TokenStore& tokens, const std::string& authorization,
                       const std::string& cookie) {
  auto who = tokens.find(token_from_headers(authorization, cookie));
  if (!who) throw HttpError(401, "missing or invalid token");
  return *who;
}

struct HttpApi::Impl {
  HttpConfig config;
  ShoreContext ctx;
  httplib::Server server;
  std::atomic<bool> stop_requested{false};
  std::atomic<bool> served{false};  ///< serve() has returned

  Impl(HttpConfig c, ShoreContext context) : config(std::move(c)), ctx(context) {}

  std::optional<Principal> principal(const httplib::Request& req) const {
    return ctx.tokens.find(
        token_from_headers(req.get_header_value("Authorization"), req.get_header_value("Cookie")));
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
      json j = {{"status", store_error.empty() ? "ok" : "degraded"},
                {"boats", ctx.fleet.boats().size()},
                {"stream_clients", ctx.hub.clients()},
                {"samples_committed", ctx.store.committed()}};
      if (!store_error.empty()) j["store_error"] = store_error;
      // The writer: a failing disk shows as a backlog, refused samples and the next retry.
      const StoreHealth sh = ctx.store.health();
      j["store"] = {{"failing", sh.failing},
                    {"backlog", sh.backlog},
                    {"dropped", sh.dropped},
                    {"failed_commits", sh.failed_commits},
                    {"retry_in_s", sh.retry_in_s}};
      if (sh.failing || sh.dropped > 0) j["status"] = "degraded";
      // Two nodes sailing with one boat id: flagged (their samples still share sessions).
      json duplicates = json::array();
      for (const auto& d : ctx.store.duplicate_ids())
        duplicates.push_back({{"boat_id", d.boat_id}, {"runs", {d.boot_a, d.boot_b}}});
      if (!duplicates.empty()) {
        j["duplicate_boat_ids"] = duplicates;
        j["status"] = "degraded";
      }
      res.set_content(j.dump(), "application/json");
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
      res.set_content(json{{"role", role_name(who->role)}}.dump(), "application/json");
    });
    server.Get("/api/v1/me", [this](const httplib::Request& req, httplib::Response& res) {
      const Principal who = authenticate(ctx.tokens, req.get_header_value("Authorization"),
                                         req.get_header_value("Cookie"));
      res.set_content(json{{"role", role_name(who.role)},
                           {"boat_id", who.boat_id.empty() ? json(nullptr) : json(who.boat_id)}}
                          .dump(),
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
      // The current fleet first, so a new dashboard draws at once; then live updates.
      std::string snapshot = "retry: 2000\n\n";
      for (const auto& b : ctx.fleet.boats()) {
        if (!only || *only == b.last.boat_id)
          snapshot += "event: sample\ndata: " + boat_json(b) + "\n\n";
      }
      res.set_chunked_content_provider(
          "text/event-stream",
          [this, client, pending = std::move(snapshot)](std::size_t,
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
            return sink.write(out.data(), out.size());
          },
          [this, client](bool) { ctx.hub.disconnect(client); });
    });
    register_rest_routes(server, ctx);
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
