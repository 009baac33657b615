#include "http_guard.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <string>

namespace telltale::shore {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

/// Per connection, for the handler-side hooks (the handler runs on the connection's thread).
struct Connection {
  int fd = -1;
  bool close_after = false;
  int cut = 0;  ///< the current request: 1 too slow, 2 too large
};
thread_local Connection* tl_connection = nullptr;

/// poll() one fd for `events` up to `timeout`; true when ready.
bool wait_for(int fd, short events, milliseconds timeout) {
  pollfd p{fd, events, 0};
  for (;;) {
    const int r = ::poll(&p, 1, static_cast<int>(std::max<milliseconds::rep>(0, timeout.count())));
    if (r < 0 && errno == EINTR) continue;
    return r > 0 && (p.revents & (events | POLLHUP | POLLERR)) != 0;
  }
}

void ip_and_port(const sockaddr_storage& addr, std::string& ip, int& port) {
  char buf[INET6_ADDRSTRLEN] = "";
  if (addr.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    ::inet_ntop(AF_INET, &a->sin_addr, buf, sizeof buf);
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    ::inet_ntop(AF_INET6, &a->sin6_addr, buf, sizeof buf);
    port = ntohs(a->sin6_port);
  }
  ip = buf;
}

/// The socket stream of one connection, buffered (the library reads the head a byte at a time),
/// with the head and body deadlines and the head's size limits.
class GuardedStream final : public httplib::Stream {
 public:
  GuardedStream(int fd, GuardedServer& server, Connection& conn)
      : fd_(fd), server_(server), conn_(conn) {}

  enum class Cut { kNone, kSlow, kLarge };

  /// Waits for the next request's first byte: false when the connection stays idle too long (the
  /// limit shrinks while threads are short) or the server stops.
  bool wait_request(const std::atomic<socket_t>& svr_sock) {
    if (pos_ < len_) return true;
    const auto start = Clock::now();
    for (;;) {
      if (svr_sock == INVALID_SOCKET) return false;
      const auto limit = server_.short_of_threads() ? server_.limits().busy_idle_timeout
                                                    : server_.limits().idle_timeout;
      const auto left = std::chrono::duration_cast<milliseconds>(start + limit - Clock::now());
      if (left.count() <= 0) {
        if (limit == server_.limits().busy_idle_timeout) server_.count_cut_idle();
        return false;
      }
      if (wait_for(fd_, POLLIN, std::min(left, milliseconds(50)))) return true;
    }
  }

  void begin_request() {
    in_head_ = true;
    head_bytes_ = 0;
    head_lines_ = 0;
    line_chars_ = 0;
    cut_ = Cut::kNone;
    conn_.cut = 0;
    wrote_ = false;
    request_start_ = Clock::now();
  }
  [[nodiscard]] Cut cut() const { return cut_; }
  [[nodiscard]] bool wrote() const { return wrote_; }

  bool is_readable() const override {
    return pos_ < len_ || wait_for(fd_, POLLIN, server_.limits().io_timeout);
  }
  bool is_writable() const override { return wait_for(fd_, POLLOUT, server_.limits().io_timeout); }

  ssize_t read(char* ptr, std::size_t size) override {
    if (cut_ != Cut::kNone) return -1;
    if (pos_ == len_ && !refill()) return -1;
    if (len_ == 0) return 0;  // orderly close
    std::size_t n = std::min(size, len_ - pos_);
    if (in_head_) n = take_head(n);
    if (cut_ != Cut::kNone) return -1;
    std::copy_n(buf_ + pos_, n, ptr);
    pos_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    if (!is_writable()) return -1;
    const ssize_t n = ::send(fd_, ptr, size, MSG_NOSIGNAL);
    if (n > 0) wrote_ = true;
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (::getpeername(fd_, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
      ip_and_port(addr, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
      ip_and_port(addr, ip, port);
  }
  socket_t socket() const override { return fd_; }

 private:
  /// Reads more into the buffer before the request's deadline. False on timeout or error (then
  /// `cut_` says whether it was the deadline); true with len_ == 0 on an orderly close.
  bool refill() {
    const auto& l = server_.limits();
    for (;;) {
      Clock::time_point deadline;
      if (in_head_) {
        deadline =
            request_start_ + (server_.short_of_threads() ? l.busy_head_timeout : l.head_timeout);
      } else {
        deadline = body_start_ + l.body_timeout;
      }
      const auto now = Clock::now();
      if (now >= deadline) {
        cut_ = Cut::kSlow;
        conn_.cut = 1;
        server_.count_cut_request();
        return false;
      }
      // Short slices: a deadline that shrinks (threads got short) is seen within 50 ms.
      const auto slice = std::min({std::chrono::duration_cast<milliseconds>(deadline - now),
                                   milliseconds(50), l.io_timeout});
      if (!wait_for(fd_, POLLIN, slice)) {
        if (now - last_data_ > l.io_timeout && !in_head_) return false;
        continue;
      }
      const ssize_t n = ::recv(fd_, buf_, sizeof buf_, 0);
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n < 0) return false;
      pos_ = 0;
      len_ = static_cast<std::size_t>(n);
      last_data_ = Clock::now();
      return true;
    }
  }

  /// Accounts up to `n` head bytes at pos_; stops after the blank line that ends the head.
  std::size_t take_head(std::size_t n) {
    const auto& l = server_.limits();
    std::size_t i = 0;
    while (i < n && in_head_) {
      const char c = buf_[pos_ + i++];
      if (++head_bytes_ > l.head_max_bytes) {
        cut_ = Cut::kLarge;
        conn_.cut = 2;
        server_.count_cut_request();
        return i;
      }
      if (c == '\n') {
        if (++head_lines_ > l.head_max_lines) {
          cut_ = Cut::kLarge;
          conn_.cut = 2;
          server_.count_cut_request();
          return i;
        }
        if (line_chars_ == 0 && head_lines_ > 1) {
          in_head_ = false;
          body_start_ = Clock::now();
        }
        line_chars_ = 0;
      } else if (c != '\r') {
        ++line_chars_;
      }
    }
    return i;
  }

  int fd_;
  GuardedServer& server_;
  Connection& conn_;
  char buf_[4096];
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  bool in_head_ = true;
  std::size_t head_bytes_ = 0;
  std::size_t head_lines_ = 0;
  std::size_t line_chars_ = 0;
  Cut cut_ = Cut::kNone;
  bool wrote_ = false;
  Clock::time_point request_start_ = Clock::now();
  Clock::time_point body_start_ = Clock::now();
  Clock::time_point last_data_ = Clock::now();
};

void write_error(int fd, int status, const char* reason, const std::string& message) {
  const std::string body = "{\"error\":\"" + message + "\"}";
  const std::string head = "HTTP/1.1 " + std::to_string(status) + " " + reason +
                           "\r\nContent-Type: application/json\r\nConnection: close\r\n"
                           "Content-Length: " +
                           std::to_string(body.size()) + "\r\n\r\n";
  const std::string all = head + body;
  if (wait_for(fd, POLLOUT, milliseconds(1000)))
    (void)::send(fd, all.data(), all.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

}  // namespace

GuardedServer::GuardedServer(GuardLimits limits) : limits_(limits) {
  const std::size_t n = limits_.workers;
  new_task_queue = [n] { return new httplib::ThreadPool(n); };
}

void GuardedServer::close_after_response() {
  if (tl_connection) tl_connection->close_after = true;
}

bool GuardedServer::request_too_large() { return tl_connection && tl_connection->cut == 2; }

void GuardedServer::cap_send_buffer(int bytes) {
  if (tl_connection)
    (void)::setsockopt(tl_connection->fd, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
  busy_.fetch_add(1);
  Connection conn{sock, false};
  tl_connection = &conn;
  GuardedStream strm(sock, *this, conn);
  bool ret = false;
  // Same keep-alive contract as the library's loop, with our idle limit and stream.
  std::size_t count = keep_alive_max_count_;
  while (count > 0 && strm.wait_request(svr_sock_)) {
    strm.begin_request();
    bool closed = false;
    ret = process_request(strm, count == 1, closed, [](httplib::Request&) {});
    if (strm.cut() != GuardedStream::Cut::kNone && !strm.wrote()) {
      if (strm.cut() == GuardedStream::Cut::kLarge) {
        write_error(sock, 431, "Request Header Fields Too Large",
                    "request line and headers too large (at most " +
                        std::to_string(limits_.head_max_bytes) + " bytes in " +
                        std::to_string(limits_.head_max_lines) + " lines)");
      } else {
        write_error(sock, 408, "Request Timeout", "request not received in time");
      }
      ret = false;
    }
    if (!ret || closed || conn.close_after) break;
    --count;
  }
  tl_connection = nullptr;
  if (conn.close_after) {
    // A body refused unread (413 at once): the client may still be sending it and reads our
    // answer only once it has. Closing now would reset the connection under it and lose the
    // answer, so the write side is shut (the answer, then FIN) and what still comes is read and
    // dropped for at most 1 s: enough for a body on any link that matters, too short to hold a
    // thread for a hostile sender.
    ::shutdown(sock, SHUT_WR);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    char sink[16384];
    for (auto now = std::chrono::steady_clock::now(); now < until;
         now = std::chrono::steady_clock::now()) {
      pollfd p{sock, POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - now);
      if (::poll(&p, 1, static_cast<int>(left.count()) + 1) <= 0) break;
      if (::recv(sock, sink, sizeof sink, 0) <= 0) break;
    }
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  busy_.fetch_sub(1);
  return ret;
}

}  // namespace telltale::shore
