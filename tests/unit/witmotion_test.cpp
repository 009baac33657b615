// WitMotion / JY901 protocol: golden packets from the manual's formulas, round trips, garbage,
// fuzzing, and a real pseudo-terminal between a writer and WitMotionSerial.
#include "witmotion.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

namespace telltale::sensors {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;

std::vector<std::uint8_t> bytes(std::initializer_list<int> v) {
  std::vector<std::uint8_t> out;
  for (int b : v) out.push_back(static_cast<std::uint8_t>(b));
  return out;
}
void add_sum(std::vector<std::uint8_t>& p) {
  unsigned s = 0;
  for (std::size_t i = p.size() - 10; i < p.size(); ++i) s += p[i];
  p.push_back(static_cast<std::uint8_t>(s & 0xFF));
}

WitSample make_sample(double t, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  WitSample s;
  s.imu.t_s = t;
  s.imu.acc_body_m_s2 = {3 * u(rng), 3 * u(rng), kG + 3 * u(rng)};
  s.imu.gyro_body_rad_s = {2 * u(rng), 2 * u(rng), 2 * u(rng)};
  s.has_gyro = true;
  s.mag_uT = {20 * u(rng), 20 * u(rng), -44 + 5 * u(rng)};
  s.has_mag = true;
  s.angle_deg = {30 * u(rng), 20 * u(rng), 170 * u(rng)};
  s.has_angle = true;
  s.pressure_pa = 101325 + 500 * u(rng);
  s.height_m = 30 + 10 * u(rng);
  s.has_pressure = true;
  s.temperature_c = 25.5;
  return s;
}

void expect_close(const WitSample& got, const WitSample& want) {
  const WitMotionParams p;
  const double q_acc = p.acc_range_g * kG / 32768.0;
  const double q_gyro = p.gyro_range_deg_s * M_PI / 180.0 / 32768.0;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(got.imu.acc_body_m_s2[a], want.imu.acc_body_m_s2[a], q_acc);
    EXPECT_NEAR(got.imu.gyro_body_rad_s[a], want.imu.gyro_body_rad_s[a], q_gyro);
    EXPECT_NEAR(got.mag_uT[a], want.mag_uT[a], p.mag_uT_per_lsb);
    EXPECT_NEAR(got.angle_deg[a], want.angle_deg[a], 180.0 / 32768.0);
  }
  EXPECT_NEAR(got.pressure_pa, want.pressure_pa, 0.5);
  EXPECT_NEAR(got.height_m, want.height_m, 0.005);
  EXPECT_NEAR(got.temperature_c, want.temperature_c, 0.005);
}

// Golden: an acceleration packet built from the manual's formula a = raw/32768*16 g.
TEST(WitMotionDecoder, DecodesManualAccelerationAndGyroPackets) {
  std::vector<WitSample> got;
  WitMotionDecoder dec([&](const WitSample& s) { got.push_back(s); });
  // ax = 0x0800 = 2048 -> 1 g; ay = 0xF800 = -2048 -> -1 g; az = 0x1000 -> 2 g; T = 2550 -> 25.5.
  auto acc = bytes({0x55, 0x51, 0x00, 0x08, 0x00, 0xF8, 0x00, 0x10, 0xF6, 0x09});
  add_sum(acc);
  // wx = 0x4000 = 16384 -> 1000 deg/s; wy = 0; wz = 0xC000 -> -1000 deg/s.
  auto gyro = bytes({0x55, 0x52, 0x00, 0x40, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x00});
  add_sum(gyro);
  // P = 101325 Pa = 0x00018BCD; H = -250 cm = 0xFFFFFF06.
  auto pres = bytes({0x55, 0x56, 0xCD, 0x8B, 0x01, 0x00, 0x06, 0xFF, 0xFF, 0xFF});
  add_sum(pres);
  std::vector<std::uint8_t> stream;
  for (int k = 0; k < 3; ++k) {
    stream.insert(stream.end(), acc.begin(), acc.end());
    stream.insert(stream.end(), gyro.begin(), gyro.end());
    stream.insert(stream.end(), pres.begin(), pres.end());
  }
  dec.feed(stream, 1.0);
  dec.flush();
  ASSERT_EQ(got.size(), 3u);
  for (const auto& s : got) {
    EXPECT_DOUBLE_EQ(s.imu.acc_body_m_s2.x(), kG);
    EXPECT_DOUBLE_EQ(s.imu.acc_body_m_s2.y(), -kG);
    EXPECT_DOUBLE_EQ(s.imu.acc_body_m_s2.z(), 2 * kG);
    EXPECT_DOUBLE_EQ(s.temperature_c, 25.5);
    EXPECT_NEAR(s.imu.gyro_body_rad_s.x(), 1000.0 * M_PI / 180.0, 1e-12);
    EXPECT_NEAR(s.imu.gyro_body_rad_s.z(), -1000.0 * M_PI / 180.0, 1e-12);
    EXPECT_DOUBLE_EQ(s.pressure_pa, 101325.0);
    EXPECT_DOUBLE_EQ(s.height_m, -2.5);
    EXPECT_FALSE(s.has_mag);
  }
  EXPECT_EQ(dec.stats().frames, 9u);
  EXPECT_EQ(dec.stats().bad_checksum, 0u);
}

TEST(WitMotionDecoder, EncoderRoundTripsWithinOneCount) {
  std::mt19937 rng(5);
  std::vector<WitSample> got, want;
  WitMotionDecoder dec([&](const WitSample& s) { got.push_back(s); });
  for (int k = 0; k < 200; ++k) {
    want.push_back(make_sample(k * 0.01, rng));
    dec.feed(encode_wit_sample(want.back()), k * 0.01);
  }
  dec.flush();
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < got.size(); ++k) expect_close(got[k], want[k]);
}

// Given garbage (including stray 0x55 bytes) and corrupted packets between good ones, when the
// stream is decoded, then every intact sample comes out and the damage is counted.
TEST(WitMotionDecoder, ResynchronisesAfterGarbageAndCountsBadFrames) {
  std::mt19937 rng(9);
  std::vector<WitSample> got, want;
  WitMotionDecoder dec([&](const WitSample& s) { got.push_back(s); });
  std::vector<std::uint8_t> stream;
  std::uniform_int_distribution<int> byte(0, 255);
  int corrupted = 0;
  for (int k = 0; k < 300; ++k) {
    auto enc = encode_wit_sample(make_sample(k * 0.01, rng));
    if (k % 10 == 3) {
      enc[11 + 4] ^= 0x5A;  // corrupt the gyro packet of this sample: its checksum fails
      ++corrupted;
    } else {
      rng.seed(static_cast<unsigned>(9 + k));
      want.push_back(make_sample(0, rng));
      rng.seed(static_cast<unsigned>(9 + k));
      enc = encode_wit_sample(make_sample(k * 0.01, rng));
    }
    stream.insert(stream.end(), enc.begin(), enc.end());
    const int junk = byte(rng) % 7;
    for (int j = 0; j < junk; ++j)
      stream.push_back(j == 0 ? 0x55 : static_cast<std::uint8_t>(byte(rng)));
  }
  // Feed in irregular chunks, as a serial port delivers them.
  std::size_t i = 0;
  while (i < stream.size()) {
    const std::size_t n =
        std::min<std::size_t>(1 + static_cast<std::size_t>(byte(rng)) % 40, stream.size() - i);
    dec.feed(std::span<const std::uint8_t>(stream.data() + i, n), 0.0);
    i += n;
  }
  dec.flush();
  EXPECT_GE(dec.stats().bad_checksum, static_cast<std::uint64_t>(corrupted));
  EXPECT_GT(dec.stats().skipped_bytes, 0u);
  // Every intact sample is decoded (garbage can at worst split one with a false frame).
  std::size_t matched = 0;
  for (const auto& w : want)
    for (const auto& g : got)
      if (g.has_gyro && std::abs(g.imu.acc_body_m_s2.x() - w.imu.acc_body_m_s2.x()) < 0.005 &&
          std::abs(g.pressure_pa - w.pressure_pa) < 0.6) {
        ++matched;
        break;
      }
  EXPECT_GE(matched, want.size() - 3);
}

TEST(WitMotionDecoder, RandomBytesNeverCrash) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> byte(0, 255);
  std::size_t samples = 0;
  WitMotionDecoder dec([&](const WitSample& s) {
    ++samples;
    EXPECT_TRUE(s.imu.acc_body_m_s2.allFinite());
  });
  std::vector<std::uint8_t> junk(200000);
  for (auto& b : junk) b = static_cast<std::uint8_t>(byte(rng) < 40 ? 0x55 : byte(rng));
  dec.feed(junk, 0.0);
  dec.flush();
  EXPECT_EQ(dec.stats().samples, samples);
  EXPECT_GT(dec.stats().skipped_bytes + dec.stats().bad_checksum, 10000u);
}

// A real pseudo-terminal: packets and garbage written to the master come out parsed from the
// slave through the termios reader.
TEST(WitMotionSerial, ReadsPacketsThroughAPseudoTerminal) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string slave = ::ptsname(master);
  std::vector<WitSample> got;
  WitMotionSerial serial(slave, 115200, [&](const WitSample& s) { got.push_back(s); });
  std::mt19937 rng(3);
  std::vector<WitSample> want;
  std::vector<std::uint8_t> stream = {0x00, 0x55, 0x13, 0x0D, 0x0A, 0xFF};  // leading garbage
  for (int k = 0; k < 50; ++k) {
    want.push_back(make_sample(k * 0.01, rng));
    const auto enc = encode_wit_sample(want.back());
    stream.insert(stream.end(), enc.begin(), enc.end());
    if (k % 7 == 0) stream.insert(stream.end(), {0x55, 0x51, 0x03});  // truncated packet
  }
  // The last sample is only emitted once the next cycle starts: send one more acc packet.
  const auto tail = encode_wit_packet(0x51, {0, 0, 2048, 0});
  stream.insert(stream.end(), tail.begin(), tail.end());
  ASSERT_EQ(::write(master, stream.data(), stream.size()), static_cast<ssize_t>(stream.size()));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (got.size() < want.size() && std::chrono::steady_clock::now() < deadline)
    ASSERT_TRUE(serial.poll_once(50));
  ::close(master);
  // The truncated packets swallow the start of the sample after them (resync) — count those.
  EXPECT_GE(got.size(), want.size() - 8);
  std::size_t matched = 0;
  for (const auto& g : got)
    for (const auto& w : want)
      if (std::abs(g.pressure_pa - w.pressure_pa) < 0.6 && g.has_gyro && g.has_mag &&
          std::abs(g.imu.acc_body_m_s2.x() - w.imu.acc_body_m_s2.x()) < 0.005) {
        expect_close(g, w);
        ++matched;
        break;
      }
  EXPECT_GE(matched, want.size() - 8);
  EXPECT_GT(serial.stats().skipped_bytes, 0u);
}

TEST(WitMotionSerial, MissingDeviceAndBadBaudThrow) {
  EXPECT_THROW(WitMotionSerial("/nonexistent/tty", 115200, nullptr), std::system_error);
  EXPECT_THROW(WitMotionSerial("/dev/null", 12345, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace telltale::sensors
