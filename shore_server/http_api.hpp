#pragma once
/// \file
/// The shore's HTTP face: REST under /api/v1 (SPEC section 6, described in openapi.json), the live
/// stream (SSE), and the static dashboard from web/. One class owns the cpp-httplib server and its
/// configuration; the routes live in rest_routes.cpp.

#include <memory>
#include <string>

#include "alarm_service.hpp"
#include "auth.hpp"
#include "fleet.hpp"
#include "ingest.hpp"
#include "live_hub.hpp"
#include "store.hpp"

namespace httplib {
class Server;
}

namespace telltale::shore {

struct HttpConfig {
  std::string bind_address = "127.0.0.1";
  int port = 8080;      ///< 0: pick a free port
  std::string web_dir;  ///< static dashboard files
  std::size_t max_stream_clients = 64;
  std::size_t rest_threads = 8;  ///< workers beyond the ones the streams may hold
  std::size_t max_body_bytes = 1 << 20;
  /// Largest file POST /api/v1/imports takes (every other route keeps max_body_bytes).
  std::size_t max_import_bytes = std::size_t{256} << 20;
  /// Where uploads wait for their import; empty: a folder in the system's temporary directory.
  std::string import_spool_dir;
  /// Pool threads beyond streams and REST workers: idle keep-alive and slow connections may hold
  /// these before the server tightens its limits (http_guard.hpp).
  std::size_t spare_threads = 32;
  /// An idle keep-alive connection is closed after this long (sooner while threads are short).
  int keep_alive_s = 5;
  /// Send buffer of a live-stream connection at its start: a client that stops reading is
  /// dropped once this and its receive buffer are full and a write has waited 5 s. It grows to
  /// hold the stream's biggest batch (a big fleet), up to kMaxStreamSendBuffer.
  std::size_t stream_send_buffer_bytes = 32 * 1024;
};

/// The most a live stream's send buffer grows to: a batch of ~5000 boats.
inline constexpr std::size_t kMaxStreamSendBuffer = 4 * 1024 * 1024;

/// What the routes work on.
struct ShoreContext {
  FleetModel& fleet;
  LiveHub& hub;
  TokenStore& tokens;
  Store& store;
  AlarmService& alarms;
  /// The DDS door's counts (ingest.hpp), shown by /healthz; none without DDS.
  const IngestCounters* ingest = nullptr;
};

class HttpApi {
 public:
  HttpApi(HttpConfig config, ShoreContext context);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  /// Binds the listening socket; returns the port. Throws std::runtime_error.
  int bind();
  /// Serves until stop(); call on a thread of its own.
  void serve();
  /// Makes serve() return, also when it has not started listening yet (cpp-httplib ignores a
  /// stop before its listen loop runs: the server would then serve forever). Returns once
  /// serve() has returned; serve() must have been called, or be called, on another thread.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Registers the data routes (boats, sessions, attitude, export, alarms) on `server`.
void register_rest_routes(httplib::Server& server, ShoreContext& context);

/// The principal of a request; throws HttpError 401 if it has no valid token.
[[nodiscard]] Principal authenticate(const TokenStore& tokens, const std::string& authorization,
                                     const std::string& cookie);

}  // namespace telltale::shore
