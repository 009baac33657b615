// The boat's GNSS input (boat_node/gnss_input.hpp) stamps every fix and wind reading on the
// run's clock (boat_node/run_clock.hpp) when it arrives, so a wall clock that steps during a run
// cannot give two records of the run one time.
#include "gnss_input.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "nmea_sentence.hpp"
#include "run_clock.hpp"

using namespace telltale::boat;
using telltale::test::nmea;
using Steady = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {
// 2001-09-09: a run clock far from today's wall clock, so a stamp read from the wall clock
// instead of the run clock cannot pass.
constexpr std::uint64_t kRunStart = 1000000000000000000ull;

class UdpSender {
 public:
  explicit UdpSender(int port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<std::uint16_t>(port));
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~UdpSender() { ::close(fd_); }
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  void send(const std::string& s) const {
    (void)::sendto(fd_, s.data(), s.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

/// One receiver epoch at 12:40:SS on 2 Dec 2026, `north_m` north of 54.34 N 10.19 E, 3 m/s.
std::string epoch(int second, double north_m) {
  char pos[64];
  const double lat_min = 0.34 * 60.0 + north_m / 1853.2;
  std::snprintf(pos, sizeof pos, "54%07.4f,N,01011.4000,E", lat_min);
  const std::string hms =
      "1240" + std::string(second < 10 ? "0" : "") + std::to_string(second) + ".00";
  return nmea("GNRMC," + hms + ",A," + pos + ",5.83,0.0,021226,,,A") +
         nmea("GNGGA," + hms + "," + pos + ",1,10,0.8,5.0,M,40.0,M,,");
}

template <class Take>
auto wait_for(Take take) {
  const auto deadline = Steady::now() + 5s;
  auto got = take();
  while (got.empty() && Steady::now() < deadline) {
    std::this_thread::sleep_for(10ms);
    got = take();
  }
  return got;
}
}  // namespace

TEST(RunClock, AdvancesWithTheMonotonicClockFromTheWallClockReadOnce) {
  const auto start = Steady::now();
  const RunClock clock(start, kRunStart);
  EXPECT_EQ(clock.at(start), kRunStart);
  EXPECT_EQ(clock.at(start - 1s), kRunStart);  // never before the run's start
  EXPECT_EQ(clock.at(start + 1500ms), kRunStart + 1500000000ull);
}

TEST(GnssInput, FixesAndWindAreStampedOnTheRunClockWhenTheyArrive) {
  const RunClock clock(Steady::now(), kRunStart);
  GnssInput in("nmea:udp:0", clock);
  ASSERT_GT(in.port(), 0);
  const UdpSender tx(in.port());

  std::uint64_t last = 0;
  for (int k = 0; k < 3; ++k) {
    const std::uint64_t before = clock.now_ns();
    tx.send(epoch(k, 3.0 * k));
    const auto fixes = wait_for([&] {
      std::vector<GnssFix> out;
      in.take(out);
      return out;
    });
    const std::uint64_t after = clock.now_ns();
    ASSERT_EQ(fixes.size(), 1u) << "epoch " << k;
    EXPECT_GE(fixes[0].t_boat_ns, before) << "epoch " << k;
    EXPECT_LE(fixes[0].t_boat_ns, after) << "epoch " << k;
    EXPECT_GT(fixes[0].t_boat_ns, last) << "epoch " << k;
    last = fixes[0].t_boat_ns;
  }
  // The gate's clock offset is this clock's: the run started in 2001, the receiver says 2026.
  EXPECT_LT(in.stats().clock_offset_s, -7e8);

  const std::uint64_t before = clock.now_ns();
  tx.send(nmea("WIMWV,45.0,R,10.0,M,A"));
  const auto winds = wait_for([&] {
    std::vector<TimedWind> out;
    in.take_wind(out);
    return out;
  });
  ASSERT_EQ(winds.size(), 1u);
  EXPECT_GE(winds[0].t_utc_ns, before);
  EXPECT_LE(winds[0].t_utc_ns, clock.now_ns());
}
