// Real sensor framing end to end: a WitMotion IMU on a pseudo-terminal (with garbage on the line)
// and an NMEA 0183 compass on loopback UDP feed a real boat_node; the shore sees the attitude
// and heading they encode.
// Eigen first: glibc's resolver headers (via httplib) define a macro _res that breaks Eigen.
#include "witmotion.hpp"
// clang-format off
#include "shore_fixture.hpp"
// clang-format on

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pty.h>
#include <signal.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cmath>

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;
constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kDeg = M_PI / 180.0;

std::string nmea(const std::string& body) {
  unsigned char cs = 0;
  for (char c : body) cs ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", cs);
  return "$" + body + tail;
}

using SerialTest = ShoreFixture;

// Given a boat heeled 10 deg to starboard and 5 deg bow down, its IMU on a serial line that also
// carries garbage, and a compass saying 123.4 deg over UDP, the shore reads those angles.
TEST_F(SerialTest, WitMotionOverPtyAndNmeaOverUdp) {
  int master = -1, slave = -1;
  char name[256];
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  termios raw{};
  tcgetattr(slave, &raw);
  cfmakeraw(&raw);
  tcsetattr(slave, TCSANOW, &raw);
  const int port = free_loopback_port(SOCK_DGRAM);
  Process& boat = start_boat(
      "serial1", {"--source", std::string("witmotion:") + name + "@115200", "--heading",
                  "nmea:udp:" + std::to_string(port), "--log-dir", dir_ + "/log"});

  std::atomic<bool> stop{false};
  std::thread imu([&] {
    const double heel = 10.0 * kDeg, pitch = -5.0 * kDeg;
    sensors::WitSample w;
    w.imu.acc_body_m_s2 = kG * Eigen::Vector3d(std::sin(pitch), std::cos(pitch) * std::sin(heel),
                                               std::cos(pitch) * std::cos(heel));
    w.imu.gyro_body_rad_s.setZero();
    w.has_gyro = true;
    const std::uint8_t garbage[] = {0x55, 0x51, 0x00, 0xFF, 0x13, 0x37, 0x55};
    for (int k = 0; !stop.load(); ++k) {
      const auto bytes = sensors::encode_wit_sample(w);
      if (::write(master, bytes.data(), bytes.size()) < 0) break;
      if (k % 50 == 0 && ::write(master, garbage, sizeof garbage) < 0) break;
      std::this_thread::sleep_for(10ms);
    }
  });
  std::thread compass([&] {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const std::string good = nmea("HEHDT,123.4,T");
    const std::string bad = "$HEHDT,999.9,T*00\r\n";  // wrong checksum: must be skipped
    while (!stop.load()) {
      ::sendto(fd, good.data(), good.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
      ::sendto(fd, bad.data(), bad.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
      std::this_thread::sleep_for(100ms);
    }
    ::close(fd);
  });

  bool ok = eventually(
      [&] {
        const auto boats = boats_by_id();
        if (!boats.count("serial1")) return false;
        const auto& b = boats.at("serial1");
        return b["heading_deg"].is_number() &&
               std::abs(b["heel_deg"].get<double>() - 10.0) < 0.5 &&
               std::abs(b["pitch_deg"].get<double>() + 5.0) < 0.5 &&
               std::abs(b["heading_deg"].get<double>() - 123.4) < 0.5;
      },
      20s);
  const auto boats = boats_by_id();
  stop = true;
  imu.join();
  compass.join();
  EXPECT_TRUE(ok) << (boats.count("serial1") ? boats.at("serial1").dump() : "no boat") << "\n"
                  << boat.output();
  EXPECT_EQ(boat.stop(SIGINT), 0);
  ::close(master);
  ::close(slave);
}

}  // namespace
}  // namespace telltale::testing
