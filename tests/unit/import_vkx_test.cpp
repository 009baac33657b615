#include <gtest/gtest.h>

#include <cmath>

#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

constexpr std::uint64_t kMs0 = 1770548200000ULL;

std::string page_header() {
  std::string s;
  put_u8(s, 0xFF);
  put_u8(s, 0x05);  // VKX 1.4
  for (int i = 0; i < 6; ++i) put_u8(s, 0);
  return s;
}

/// A PVO row with heel, pitch (bow up) and heading, composed yaw-pitch-roll in NED.
std::string pvo(std::uint64_t ms, double heel_deg, double pitch_deg, double heading_deg) {
  const double r = heel_deg * M_PI / 360.0, p = pitch_deg * M_PI / 360.0,
               y = heading_deg * M_PI / 360.0;
  const double cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p),
               cy = std::cos(y), sy = std::sin(y);
  const double w = cy * cp * cr + sy * sp * sr, x = cy * cp * sr - sy * sp * cr,
               qy = cy * sp * cr + sy * cp * sr, z = sy * cp * cr - cy * sp * sr;
  std::string s;
  put_u8(s, 0x02);
  put_u64(s, ms);
  put_u32(s, static_cast<std::uint32_t>(static_cast<std::int32_t>(395000000)));
  put_u32(s, static_cast<std::uint32_t>(static_cast<std::int32_t>(-25000000)));
  put_f32(s, 3.5f);
  put_f32(s, static_cast<float>(M_PI / 2));
  put_f32(s, 0.0f);
  put_f32(s, static_cast<float>(w));
  put_f32(s, static_cast<float>(x));
  put_f32(s, static_cast<float>(qy));
  put_f32(s, static_cast<float>(z));
  return s;
}

std::string timer(std::uint64_t ms, unsigned type, std::int32_t seconds) {
  std::string s;
  put_u8(s, 0x04);
  put_u64(s, ms);
  put_u8(s, type);
  put_u32(s, static_cast<std::uint32_t>(seconds));
  return s;
}

TEST(ImportVkx, PositionAttitudeAndEvents) {
  std::string f = page_header() + pvo(kMs0, 10.0, 5.0, 90.0) + timer(kMs0 + 100, 3, 0);
  // An internal row (0x21) and a terminator are framed by their sizes and passed over.
  put_u8(f, 0x21);
  f.append(52, '\0');
  put_u8(f, 0xFE);
  put_u16(f, 120);
  f += page_header() + pvo(kMs0 + 500, -20.0, -3.0, 350.0);
  Collect sink;
  const auto r = run(Format::kVkx, f, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  const auto& a = sink.points[0];
  EXPECT_EQ(a.t_utc_ns, kMs0 * 1000000ULL);
  EXPECT_NEAR(a.lat_deg, 39.5, 1e-9);
  EXPECT_NEAR(a.lon_deg, -2.5, 1e-9);
  EXPECT_NEAR(a.sog_m_s, 3.5, 1e-6);
  EXPECT_NEAR(a.cog_deg, 90.0, 1e-4);
  EXPECT_NEAR(a.heel_deg, 10.0, 1e-4);  // + starboard down
  EXPECT_NEAR(a.pitch_deg, 5.0, 1e-4);  // + bow up
  EXPECT_NEAR(a.heading_deg, 90.0, 1e-4);
  EXPECT_NEAR(sink.points[1].heel_deg, -20.0, 1e-4);
  EXPECT_NEAR(sink.points[1].heading_deg, 350.0, 1e-4);
  ASSERT_EQ(sink.events.size(), 1u);
  EXPECT_EQ(sink.events[0].kind, "race_start");
}

TEST(ImportVkx, UnknownKeyKeepsThePrefixAsPartial) {
  const std::string good = page_header() + pvo(kMs0, 1, 1, 1);
  std::string f = good;
  put_u8(f, 0x42);
  f += pvo(kMs0 + 500, 1, 1, 1);
  Collect sink;
  const auto r = run(Format::kVkx, f, sink);
  EXPECT_EQ(r.status, ParseStatus::kPartial);
  EXPECT_EQ(sink.points.size(), 1u);
  EXPECT_NE(r.message.find("unknown row key 0x42 at byte offset " + std::to_string(good.size())),
            std::string::npos)
      << r.message;
}

TEST(ImportVkx, TruncatedRowNamesItsOffset) {
  const std::string good = page_header() + pvo(kMs0, 1, 1, 1);
  const std::string f = good + pvo(kMs0 + 500, 1, 1, 1).substr(0, 20);
  Collect sink;
  const auto r = run(Format::kVkx, f, sink);
  EXPECT_EQ(r.status, ParseStatus::kPartial);
  EXPECT_EQ(sink.points.size(), 1u);
  EXPECT_NE(r.message.find("byte offset " + std::to_string(good.size())), std::string::npos)
      << r.message;
  // Nothing before the cut: an error, not a partial file.
  Collect none;
  EXPECT_EQ(run(Format::kVkx, page_header() + pvo(kMs0, 1, 1, 1).substr(0, 9), none).status,
            ParseStatus::kError);
  EXPECT_EQ(run(Format::kVkx, "not a vkx", none).status, ParseStatus::kError);
}

TEST(ImportVkx, ApparentWindRowsAreMadeTrueWithTheBoatsVelocity) {
  // The boat heads and sails east (pvo: COG 90 deg, 3.5 m/s); a true wind of 5 m/s from the north
  // reaches it as air moving past at (-5 north, -3.5 east): apparent from 325.0 deg on the
  // compass, 235.0 deg off the bow, at hypot(5, 3.5).
  const double awa = std::atan2(3.5, 5.0) * 180.0 / M_PI - 90.0 + 360.0;  // off the bow
  const double aws = std::hypot(5.0, 3.5);
  auto wind_row = [](std::uint64_t ms, double dir, double speed) {
    std::string s;
    put_u8(s, 0x0A);
    put_u64(s, ms);
    put_f32(s, static_cast<float>(dir));
    put_f32(s, static_cast<float>(speed));
    return s;
  };
  const std::string f = page_header() + wind_row(kMs0 - 100, awa, aws) + pvo(kMs0, 0.0, 0.0, 90.0) +
                        wind_row(kMs0 + 200, awa, aws) + wind_row(kMs0 + 1500, awa, aws);
  Collect sink;
  const auto r = run(Format::kVkx, f, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  // Before any position row and 1.5 s after the last one: no velocity to take out, no wind.
  ASSERT_EQ(sink.winds.size(), 1u);
  EXPECT_EQ(sink.winds[0].t_utc_ns, (kMs0 + 200) * 1000000ULL);
  EXPECT_NEAR(std::remainder(sink.winds[0].from_deg - 0.0, 360.0), 0.0, 1e-3);
  EXPECT_NEAR(sink.winds[0].speed_m_s, 5.0, 1e-4);
  EXPECT_STREQ(sink.winds[0].source, "vkx_apparent");
}

}  // namespace
}  // namespace telltale::shore::import
