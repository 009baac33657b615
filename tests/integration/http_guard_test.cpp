// Issue 25, findings 6, 7 and 13: the shore's HTTP edges over raw loopback sockets. Idle
// keep-alive connections, a slowloris, endless headers, a huge Content-Length, a chunked body,
// 10 000 query parameters and dashboards that stop reading must neither take HTTP down nor hold
// its threads; each gets a clear answer at once.
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>

#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

/// A TCP connection to 127.0.0.1:port; -1 on failure. `rcvbuf` > 0 sets SO_RCVBUF first.
int connect_loopback(int port, int rcvbuf = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
    if (n <= 0) return false;
    off += static_cast<std::size_t>(n);
  }
  return true;
}

/// Reads one response (head, and a body of Content-Length) or until close/timeout.
std::string read_response(int fd, std::chrono::milliseconds timeout) {
  std::string out;
  const auto deadline = Clock::now() + timeout;
  char buf[4096];
  while (Clock::now() < deadline) {
    const auto head_end = out.find("\r\n\r\n");
    if (head_end != std::string::npos) {
      const auto cl = out.find("Content-Length: ");
      if (cl != std::string::npos && cl < head_end) {
        const std::size_t len = std::stoul(out.substr(cl + 16));
        if (out.size() >= head_end + 4 + len) return out;
      }
    }
    pollfd p{fd, POLLIN, 0};
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (::poll(&p, 1, static_cast<int>(std::max<long>(1, left.count()))) <= 0) continue;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

int status_of(const std::string& response) {
  if (response.rfind("HTTP/1.1 ", 0) != 0) return -1;
  return std::stoi(response.substr(9, 3));
}

class HttpGuardTest : public ShoreFixture {
 protected:
  /// One raw request on a fresh connection: the response and the seconds it took.
  std::pair<std::string, double> raw(const std::string& request,
                                     std::chrono::milliseconds timeout = 8s) {
    const int fd = connect_loopback(port_);
    EXPECT_GE(fd, 0);
    const auto t0 = Clock::now();
    (void)send_all(fd, request);
    std::string r = read_response(fd, timeout);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    ::close(fd);
    return {r, s};
  }

  /// GET `path` on a fresh connection with a 2 s budget: its status, or -1.
  int quick_get(const std::string& path) {
    httplib::Client c("127.0.0.1", port_);
    c.set_connection_timeout(2);
    c.set_read_timeout(2);
    auto res = c.Get(path, bearer());
    return res ? res->status : -1;
  }
};

// Finding 13: a 1 GiB Content-Length used to get its 413 only after the 5 s read timeout.
TEST_F(HttpGuardTest, HugeContentLengthGets413AtOnce) {
  const auto [r, s] = raw(std::string("PUT /api/v1/alarms/rules HTTP/1.1\r\nHost: x\r\n") +
                          "Authorization: Bearer " + kCoachToken +
                          "\r\nContent-Type: application/json\r\nContent-Length: 1073741824\r\n\r\n"
                          "[");
  EXPECT_EQ(status_of(r), 413) << r;
  EXPECT_LT(s, 1.0);
  EXPECT_NE(r.find("at most 1048576 bytes"), std::string::npos) << r;
}

// Finding 13: a chunked body got a 400 saying a Content-Length was missing among other things.
TEST_F(HttpGuardTest, ChunkedBodyGetsAClearError) {
  const auto [r, s] = raw(std::string("PUT /api/v1/alarms/rules HTTP/1.1\r\nHost: x\r\n") +
                          "Authorization: Bearer " + kCoachToken +
                          "\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"
                          "2\r\n[]\r\n0\r\n\r\n");
  EXPECT_EQ(status_of(r), 411) << r;
  EXPECT_NE(r.find("chunked request bodies are not accepted"), std::string::npos) << r;
  EXPECT_LT(s, 1.0);
  EXPECT_EQ(get_json("/api/v1/alarms/rules"), json::array());  // nothing changed
}

// Finding 13: 10 000 query parameters got a vague 414 ("request failed").
TEST_F(HttpGuardTest, TenThousandQueryParametersGetAClearError) {
  std::string q;
  for (int i = 0; i < 10000; ++i) q += (i ? "&p" : "p") + std::to_string(i) + "=1";
  const auto [r, s] = raw("GET /api/v1/boats?" + q + " HTTP/1.1\r\nHost: x\r\n\r\n");
  const int status = status_of(r);
  EXPECT_TRUE(status == 414 || status == 431) << r.substr(0, 300);
  EXPECT_TRUE(r.find("query parameters") != std::string::npos ||
              r.find("too large") != std::string::npos)
      << r.substr(0, 300);
  EXPECT_LT(s, 2.0);
  // Within the line limit, too many parameters are refused by count.
  std::string few;
  for (int i = 0; i < 100; ++i) few += (i ? "&p" : "p") + std::to_string(i) + "=1";
  const auto [r2, s2] = raw("GET /api/v1/boats?" + few + " HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(status_of(r2), 400) << r2;
  EXPECT_NE(r2.find("too many query parameters"), std::string::npos) << r2;
}

// Finding 7: no limit on the number of request headers (37 MB of them grew the shore by 131 MB).
TEST_F(HttpGuardTest, EndlessHeadersAreCutWith431) {
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(send_all(fd, "GET /healthz HTTP/1.1\r\nHost: x\r\n"));
  const auto t0 = Clock::now();
  std::string header_block;
  for (int i = 0; i < 200; ++i) header_block += "X-Pad-" + std::to_string(i) + ": " + "y\r\n";
  bool cut = false;
  // Up to 4 MB of headers; the shore must stop reading long before.
  for (int i = 0; i < 1000 && !cut; ++i) cut = !send_all(fd, header_block);
  const std::string r = read_response(fd, 3s);
  EXPECT_EQ(status_of(r), 431) << r.substr(0, 200);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 5.0);
  ::close(fd);
  EXPECT_EQ(quick_get("/healthz"), 200);
}

// Finding 6: 72 idle keep-alive connections (after one unauthenticated GET /healthz each) and a
// slowloris took all HTTP down: /healthz, the dashboard and the API must still answer in 2 s.
TEST_F(HttpGuardTest, IdleAndSlowConnectionsDoNotTakeHttpDown) {
  std::vector<int> idle;
  for (int i = 0; i < 72; ++i) {
    const int fd = connect_loopback(port_);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(send_all(fd, "GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n"));
    idle.push_back(fd);
  }
  for (int fd : idle) EXPECT_EQ(status_of(read_response(fd, 5s)), 200);
  // Keep them open (idle) and add a reconnecting slowloris: 60 connections each trickling a
  // header byte every 500 ms, reconnecting whenever the shore closes one.
  std::atomic<bool> running{true};
  std::thread loris([&] {
    std::vector<int> socks(60, -1);
    while (running) {
      for (int& fd : socks) {
        if (fd < 0) {
          fd = connect_loopback(port_);
          if (fd >= 0 && !send_all(fd, "GET /healthz HTTP/1.1\r\nHost: x\r\n")) {
            ::close(fd);
            fd = -1;
          }
          continue;
        }
        if (!send_all(fd, "X")) {
          ::close(fd);
          fd = -1;
        }
      }
      std::this_thread::sleep_for(500ms);
    }
    for (int fd : socks)
      if (fd >= 0) ::close(fd);
  });
  std::this_thread::sleep_for(2s);
  for (int round = 0; round < 4; ++round) {
    const auto t0 = Clock::now();
    EXPECT_EQ(quick_get("/healthz"), 200) << "round " << round;
    EXPECT_EQ(quick_get("/"), 200) << "round " << round;
    EXPECT_EQ(quick_get("/api/v1/boats"), 200) << "round " << round;
    EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 4.0);
    std::this_thread::sleep_for(1s);
  }
  running = false;
  loris.join();
  for (int fd : idle) ::close(fd);
  ASSERT_TRUE(shore_->running());
}

class StreamGuardTest : public HttpGuardTest {
 protected:
  std::vector<std::string> shore_flags() const override {
    return {"--max-streams", "2", "--stream-interval-ms", "20"};
  }
};

// Finding 6: a dashboard that stops reading held its stream slot for minutes (the kernel grows
// the send buffer to megabytes before a write ever blocks).
TEST_F(StreamGuardTest, NonReadingStreamClientsLoseTheirSlotInSeconds) {
  start_boat("sg1");
  std::vector<int> stuck;
  for (int i = 0; i < 2; ++i) {
    const int fd = connect_loopback(port_, 4096);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(send_all(fd, std::string("GET /api/v1/stream HTTP/1.1\r\nHost: x\r\n") +
                                 "Authorization: Bearer " + kCoachToken + "\r\n\r\n"));
    stuck.push_back(fd);
  }
  ASSERT_TRUE(eventually(
      [&] {
        const json h = get_json("/healthz");
        return h.is_object() && h["stream_clients"] == 2;
      },
      5s));
  // Never read: the slots must come free while the boat keeps sailing.
  const auto t0 = Clock::now();
  EXPECT_TRUE(eventually(
      [&] {
        const json h = get_json("/healthz");
        return h.is_object() && h["stream_clients"] == 0;
      },
      45s))
      << "non-reading clients still hold the stream slots";
  std::printf("slots free after %.1f s\n",
              std::chrono::duration<double>(Clock::now() - t0).count());
  for (int fd : stuck) ::close(fd);
}

}  // namespace
}  // namespace telltale::testing
