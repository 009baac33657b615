#pragma once
/// \file
/// The shore's HTTP face: REST under /api/v1 (SPEC section 6), the live stream (SSE), and the
/// static dashboard from web/. One class owns the cpp-httplib server and its configuration.

#include <memory>
#include <string>

#include "auth.hpp"
#include "fleet.hpp"
#include "live_hub.hpp"
#include "store.hpp"

namespace telltale::shore {

struct HttpConfig {
  std::string bind_address = "127.0.0.1";
  int port = 8080;                   ///< 0: pick a free port
  std::string web_dir;               ///< static dashboard files
  std::size_t max_stream_clients = 64;
  std::size_t rest_threads = 8;      ///< workers beyond the ones the streams may hold
  std::size_t max_body_bytes = 1 << 20;
};

class HttpApi {
 public:
  HttpApi(HttpConfig config, FleetModel& fleet, LiveHub& hub, TokenStore& tokens,
          SampleStore& store);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  /// Binds the listening socket; returns the port. Throws std::runtime_error.
  int bind();
  /// Serves until stop(); call on a thread of its own.
  void serve();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The JSON of one boat as /api/v1/boats and the stream present it.
[[nodiscard]] std::string boat_json(const BoatView& view);
/// ISO-8601 UTC with milliseconds for ns since 1970.
[[nodiscard]] std::string iso8601(std::uint64_t t_utc_ns);

}  // namespace telltale::shore
