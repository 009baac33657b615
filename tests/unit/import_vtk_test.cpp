#include <gtest/gtest.h>

#include <cmath>

#include "import_support.hpp"
#include "vtk.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

std::string record(const std::string& body) {
  std::string s;
  put_u16(s, static_cast<unsigned>(body.size()));
  return s + body;
}

/// A trackpoint whose quaternion is the vendor's z-up frame: heel (roll), bow-up pitch (a
/// negative rotation about y) and magnetic heading (a negative rotation about z).
std::string trackpoint(std::uint32_t seconds, std::uint32_t cs, double heel, double pitch,
                       double mag_heading) {
  const double r = heel * M_PI / 360.0, p = -pitch * M_PI / 360.0, y = -mag_heading * M_PI / 360.0;
  const double cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p),
               cy = std::cos(y), sy = std::sin(y);
  const double w = cy * cp * cr + sy * sp * sr, x = cy * cp * sr - sy * sp * cr,
               qy = cy * sp * cr + sy * cp * sr, z = sy * cp * cr - cy * sp * sr;
  std::string tp;
  pb_uint(tp, 1, seconds);
  pb_uint(tp, 2, cs);
  pb_sint(tp, 3, 395000000);
  pb_sint(tp, 4, -25000000);
  pb_uint(tp, 5, 65);  // 6.5 kn
  pb_uint(tp, 6, 270);
  pb_sint(tp, 7, std::lround(w * 1000));
  pb_sint(tp, 8, std::lround(x * 1000));
  pb_sint(tp, 9, std::lround(qy * 1000));
  pb_sint(tp, 10, std::lround(z * 1000));
  std::string rec;
  pb_bytes(rec, 1, tp);
  return record(rec);
}

std::string declination(int deg) {
  std::string d, rec;
  pb_sint(d, 1, deg);
  pb_bytes(rec, 18, d);
  return record(rec);
}

std::string hardware(int serial) {
  std::string h, rec;
  pb_uint(h, 1, 7);
  pb_uint(h, 4, static_cast<std::uint64_t>(serial));
  pb_bytes(rec, 17, h);
  return record(rec);
}

std::string button(unsigned type) {
  std::string b, rec;
  pb_uint(b, 1, type);
  pb_bytes(rec, 16, b);
  return record(rec);
}

TEST(ImportVtk, TrackpointsDeclinationDeviceAndButtons) {
  const std::string f = hardware(1234) + declination(-3) +
                        trackpoint(1770548200, 25, 12.0, 4.0, 100.0) + button(2) +
                        trackpoint(1770548200, 75, -8.0, -2.0, 5.0);
  Collect sink;
  const auto r = run(Format::kVtk, f, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.device_name, "Velocitek model 7 serial 1234");
  const auto& a = sink.points[0];
  EXPECT_EQ(a.t_utc_ns, 1770548200250000000ULL);
  EXPECT_NEAR(a.lat_deg, 39.5, 1e-9);
  EXPECT_NEAR(a.lon_deg, -2.5, 1e-9);
  EXPECT_NEAR(a.sog_m_s, 6.5 * 1852.0 / 3600.0, 1e-9);
  EXPECT_DOUBLE_EQ(a.cog_deg, 270.0);
  // The quaternion is stored in thousandths: angles within ~0.2 deg.
  EXPECT_NEAR(a.heel_deg, 12.0, 0.2);
  EXPECT_NEAR(a.pitch_deg, 4.0, 0.2);
  EXPECT_NEAR(a.heading_deg, 97.0, 0.2);  // magnetic 100, declination 3 W
  EXPECT_NEAR(sink.points[1].heel_deg, -8.0, 0.2);
  EXPECT_NEAR(sink.points[1].heading_deg, 2.0, 0.2);
  ASSERT_EQ(sink.events.size(), 1u);
  EXPECT_EQ(sink.events[0].kind, "line_pin");
  EXPECT_EQ(sink.events[0].t_utc_ns, a.t_utc_ns);
}

TEST(ImportVtk, SerialNumberFromTheHead) {
  EXPECT_EQ(vtk_serial_number(declination(1) + hardware(4321) + trackpoint(1770548200, 0, 1, 1, 1)),
            4321);
  EXPECT_FALSE(vtk_serial_number(trackpoint(1770548200, 0, 1, 1, 1)));
  EXPECT_FALSE(vtk_serial_number(hardware(4321).substr(0, 4)));  // cut
}

TEST(ImportVtk, NoDeclinationNoTrueHeading) {
  Collect sink;
  ASSERT_EQ(run(Format::kVtk, trackpoint(1770548200, 0, 1, 1, 100), sink).status, ParseStatus::kOk);
  EXPECT_TRUE(std::isnan(sink.points[0].heading_deg));
  ImportOptions o;
  o.declination_deg = 2.0;
  Collect with;
  ASSERT_EQ(run(Format::kVtk, trackpoint(1770548200, 0, 1, 1, 100), with, o).status,
            ParseStatus::kOk);
  EXPECT_NEAR(with.points[0].heading_deg, 102.0, 0.2);
}

TEST(ImportVtk, TruncatedOrCorruptKeepsThePrefix) {
  const std::string good = trackpoint(1770548200, 0, 1, 1, 1);
  Collect sink;
  auto r = run(Format::kVtk, good + trackpoint(1770548201, 0, 1, 1, 1).substr(0, 10), sink);
  EXPECT_EQ(r.status, ParseStatus::kPartial);
  EXPECT_EQ(sink.points.size(), 1u);
  EXPECT_NE(r.message.find("byte offset " + std::to_string(good.size())), std::string::npos)
      << r.message;
  std::string bad = good;
  put_u16(bad, 3);
  bad += "\x0A\x7F\x01";  // a length running past the record
  Collect sink2;
  r = run(Format::kVtk, bad, sink2);
  EXPECT_EQ(r.status, ParseStatus::kPartial);
  EXPECT_NE(r.message.find("not a protobuf Record"), std::string::npos) << r.message;
  Collect none;
  EXPECT_EQ(run(Format::kVtk, "", none).status, ParseStatus::kError);
}

}  // namespace
}  // namespace telltale::shore::import
