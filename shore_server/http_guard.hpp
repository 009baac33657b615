#pragma once
/// \file
/// cpp-httplib's server with bounds on what one connection may hold. The library (0.11.4, Debian's
/// shared build) serves each connection on one pool thread for its whole life: an idle keep-alive
/// connection holds a thread for the keep-alive timeout, a slowloris holds one forever (its read
/// timeout is per recv), and headers are read without a limit on their number. So a few dozen
/// sockets could take every thread, and with them the dashboard and /healthz.
///
/// GuardedServer replaces the per-connection loop (process_and_close_socket, which the library
/// made virtual for its TLS server) and the socket stream; parsing, routing and responses stay the
/// library's:
/// - a request's line and headers must arrive within `head_timeout` (`busy_head_timeout` while
///   fewer than `spare_workers` threads are free) and within `head_max_bytes` and
///   `head_max_lines`; otherwise the connection gets a 408 or 431 and is closed;
/// - its body within `body_timeout`;
/// - an idle keep-alive connection is closed after `idle_timeout`, or `busy_idle_timeout` while
///   threads are short;
/// - every socket wait is at most `io_timeout`.
/// With these, an attacker's connection frees its thread within seconds while threads are short,
/// and the pool has room beyond the live streams for the dashboard's requests and /healthz.

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>

namespace telltale::shore {

struct GuardLimits {
  std::size_t workers = 104;       ///< pool threads (streams + REST + headroom)
  std::size_t spare_workers = 16;  ///< fewer free threads than this: "busy", tighter timeouts
  std::size_t head_max_bytes = 64 * 1024;  ///< request line + headers
  std::size_t head_max_lines = 100;        ///< request line + headers
  std::chrono::milliseconds head_timeout{10000};
  std::chrono::milliseconds busy_head_timeout{1500};
  std::chrono::milliseconds body_timeout{30000};
  std::chrono::milliseconds idle_timeout{5000};
  std::chrono::milliseconds busy_idle_timeout{100};
  std::chrono::milliseconds io_timeout{5000};
};

class GuardedServer : public httplib::Server {
 public:
  explicit GuardedServer(GuardLimits limits);

  /// From a handler: close the connection it serves once this response is written (a request
  /// whose body was not read must not be parsed as the next request).
  static void close_after_response();
  /// From a handler: fix the send buffer of the connection it serves at `bytes` (a live stream),
  /// so a client that stops reading fills it within seconds and the write timeout drops it,
  /// instead of the kernel growing the buffer to megabytes while it holds a stream slot.
  static void cap_send_buffer(int bytes);
  /// From the error handler: the request being answered had its line and headers cut for size
  /// (the library then answers 400; this makes it the 431 it is).
  [[nodiscard]] static bool request_too_large();

  /// Connections being served now (each holds a pool thread).
  [[nodiscard]] std::size_t busy() const { return busy_.load(); }
  [[nodiscard]] std::size_t workers() const { return limits_.workers; }
  /// Connections closed because their request was too slow or too large.
  [[nodiscard]] std::uint64_t cut_requests() const { return cut_requests_.load(); }
  /// Idle keep-alive connections closed early because threads were short.
  [[nodiscard]] std::uint64_t cut_idle() const { return cut_idle_.load(); }

  [[nodiscard]] bool short_of_threads() const {
    return busy_.load() + limits_.spare_workers >= limits_.workers;
  }
  [[nodiscard]] const GuardLimits& limits() const { return limits_; }

  void count_cut_request() { cut_requests_.fetch_add(1); }
  void count_cut_idle() { cut_idle_.fetch_add(1); }

 private:
  bool process_and_close_socket(socket_t sock) override;

  GuardLimits limits_;
  std::atomic<std::size_t> busy_{0};
  std::atomic<std::uint64_t> cut_requests_{0};
  std::atomic<std::uint64_t> cut_idle_{0};
};

}  // namespace telltale::shore
