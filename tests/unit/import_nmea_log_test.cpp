#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

/// "$" + body + "*hh".
std::string s(const std::string& body) {
  unsigned sum = 0;
  for (char c : body) sum ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X", sum);
  return "$" + body + tail;
}

// 2026-02-08 10:56:40 UTC
constexpr std::uint64_t kT0 = 1770548200ULL * 1000000000ULL;

TEST(ImportNmeaLog, EpochsWithHeadingHeelAndPitch) {
  const std::string log =
      s("GPRMC,105640.00,A,3930.0000,N,00230.0000,E,10.0,045.0,080226,,,A") + "\r\n" +
      s("GPGGA,105640.00,3930.0000,N,00230.0000,E,1,08,0.9,5.0,M,50.0,M,,") + "\r\n" +
      s("HCHDT,047.5,T") + "\r\n" + s("IIXDR,A,-5.5,D,ROLL,A,2.5,D,PTCH") + "\r\n" +
      "garbage line\r\n" + s("GPRMC,105641.00,A,3930.0010,N,00230.0010,E,10.0,045.0,080226,,,A") +
      "\r\n" + s("IIXDR,A,7.0,D,heel,A,1.0,D,Trim") + "\r\n" + s("WIMWV,045,R,12.0,N,A") + "\r\n" +
      // No checksum: accepted in a log.
      "$GPRMC,105642.00,A,3930.0020,N,00230.0020,E,10.0,045.0,080226,,,A\n";
  Collect sink;
  const auto r = run(Format::kNmea, log, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 3u);
  const auto& a = sink.points[0];
  EXPECT_EQ(a.t_utc_ns, kT0);
  EXPECT_NEAR(a.lat_deg, 39.5, 1e-9);
  EXPECT_NEAR(a.lon_deg, 2.5, 1e-9);
  EXPECT_NEAR(a.sog_m_s, 10.0 * 1852.0 / 3600.0, 1e-9);
  EXPECT_DOUBLE_EQ(a.cog_deg, 45.0);
  EXPECT_DOUBLE_EQ(a.heading_deg, 47.5);
  EXPECT_DOUBLE_EQ(a.heel_deg, -5.5);
  EXPECT_DOUBLE_EQ(a.pitch_deg, 2.5);
  EXPECT_EQ(sink.points[1].t_utc_ns, kT0 + 1000000000ULL);
  EXPECT_DOUBLE_EQ(sink.points[1].heel_deg, 7.0);
  EXPECT_DOUBLE_EQ(sink.points[1].pitch_deg, 1.0);
  EXPECT_TRUE(std::isnan(sink.points[2].heel_deg));  // nothing new in its epoch
  EXPECT_EQ(r.skipped, 1u);                          // the garbage line
}

TEST(ImportNmeaLog, SignalKMultiplexedLogTakesTheDateFromItsStamps) {
  // No RMC: GGA and GLL carry only the time of day; the date comes from the ms stamps.
  const std::string log =
      "1770548200000;A;" + s("GPGGA,105640.00,3930.0000,N,00230.0000,E,1,08,0.9,5.0,M,50.0,M,,") +
      "\n1770548200100;A;" + s("HEHDM,100.0,M") + "\n1770548201000;A;" +
      s("GPGLL,3930.0010,N,00230.0010,E,105641.00,A,A") + "\n1770548201050;A;" +
      s("GPVTG,045.0,T,,M,5.0,N,9.3,K,A") + "\n";
  ImportOptions o;
  o.declination_deg = 2.0;
  Collect sink;
  const auto r = run(Format::kNmea, log, sink, o);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.points[0].t_utc_ns, kT0);
  EXPECT_DOUBLE_EQ(sink.points[0].heading_deg, 102.0);
  EXPECT_EQ(sink.points[1].t_utc_ns, kT0 + 1000000000ULL);
  EXPECT_NEAR(sink.points[1].sog_m_s, 5.0 * 1852.0 / 3600.0, 1e-9);
}

TEST(ImportNmeaLog, NoDateIsAnError) {
  Collect sink;
  const auto r = run(Format::kNmea,
                     s("GPGGA,105640.00,3930.0000,N,00230.0000,E,1,08,0.9,5.0,M,50.0,M,,") + "\n",
                     sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  EXPECT_NE(r.message.find("no position with a date"), std::string::npos) << r.message;
}

// A garbled ZDA (a year of 1e300, a day of 1.5) gives no date and no undefined conversion (the
// fuzz target found the year; UBSan flags the conversion in the sanitized run of this test).
TEST(ImportNmeaLog, GarbledZdaDatesAreNoDates) {
  Collect sink;
  const std::string log = s("GPZDA,105640.00,1e300,02,2026,00,00") + "\n" +
                          s("GPZDA,105640.00,08,02,1e300,00,00") + "\n" +
                          s("GPZDA,105640.00,1.5,02,2026,00,00") + "\n" +
                          s("GPGGA,105640.00,3930.0000,N,00230.0000,E,1,08,0.9,5.0,M,50.0,M,,") + "\n";
  const auto r = run(Format::kNmea, log, sink);
  EXPECT_EQ(r.status, ParseStatus::kError) << "still no date";
  EXPECT_TRUE(sink.points.empty());
}

TEST(ImportNmeaLog, MidnightRollsTheDateOver) {
  const std::string log =
      s("GPRMC,235959.00,A,3930.0000,N,00230.0000,E,1.0,045.0,080226,,,A") + "\n" +
      s("GPGGA,000000.00,3930.0000,N,00230.0000,E,1,08,0.9,5.0,M,50.0,M,,") + "\n";
  Collect sink;
  ASSERT_EQ(run(Format::kNmea, log, sink).status, ParseStatus::kOk);
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.points[1].t_utc_ns - sink.points[0].t_utc_ns, 1000000000ULL);
}

TEST(ImportNmeaLog, RealSignalKSampleLog) {
  // A real yacht's instruments (tests/data/signalk_plaka/README.md): GLL positions, VTG, wind,
  // depth, empty heading sentences, ZDA without a date.
  std::ifstream f(std::string(TELLTALE_TEST_DATA_DIR) + "/signalk_plaka/plaka_head.log");
  ASSERT_TRUE(f);
  std::stringstream bytes;
  bytes << f.rdbuf();
  Collect refused;
  const auto no_date = run(Format::kNmea, bytes.str(), refused);
  EXPECT_EQ(no_date.status, ParseStatus::kError);
  EXPECT_NE(no_date.message.find("or the date given"), std::string::npos) << no_date.message;

  ImportOptions o;
  o.date_days = *days_from_civil(2014, 8, 15);
  Collect sink;
  const auto r = run(Format::kNmea, bytes.str(), sink, o);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 4u);  // 09:55:59, 09:56:01, :03, :05 (the ZDA/GLL epochs)
  const std::uint64_t t0 = 1408096559ULL * 1000000000ULL;  // 2014-08-15T09:55:59Z
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_EQ(sink.points[i].t_utc_ns, t0 + 2 * i * 1000000000ULL);
  EXPECT_NEAR(sink.points[0].lat_deg, 60.0 + 5.071 / 60.0, 1e-9);
  EXPECT_NEAR(sink.points[0].lon_deg, 23.0 + 32.346 / 60.0, 1e-9);
  EXPECT_NEAR(sink.points[0].sog_m_s, 5.80 * 1852.0 / 3600.0, 1e-9);  // the VTG after it
  EXPECT_DOUBLE_EQ(sink.points[0].cog_deg, 225.18);
  EXPECT_TRUE(std::isnan(sink.points[0].heading_deg));  // the log's HDT and HDM are empty
  EXPECT_GT(r.skipped, 20u);  // VHW, VPW, VWT, DBT, XTE, GSV, ... are not ours

  // Its wind: the instrument alternates MWV T (true angle off the bow) and MWV R (apparent);
  // MWD has a speed and no direction. No heading: the COG turns the angle to the compass.
  ASSERT_EQ(sink.winds.size(), 3u);  // the fourth epoch has no wind sentence
  EXPECT_EQ(sink.winds[0].t_utc_ns, t0);
  EXPECT_STREQ(sink.winds[0].source, "mwv_true");  // T outranks the R of the same epoch
  EXPECT_NEAR(sink.winds[0].from_deg, std::fmod(313.0 + 225.18, 360.0), 1e-9);
  EXPECT_NEAR(sink.winds[0].speed_m_s, 8.16 * 1852.0 / 3600.0, 1e-9);
  // 09:56:01: apparent 336 deg off the bow at 12.82 kn, COG 226.95, SOG 5.80 kn.
  const double kn = 1852.0 / 3600.0, rad = M_PI / 180.0;
  const double a = (226.95 + 336.0) * rad, c = 226.95 * rad;
  const double wn = -12.82 * kn * std::cos(a) + 5.80 * kn * std::cos(c);
  const double we = -12.82 * kn * std::sin(a) + 5.80 * kn * std::sin(c);
  EXPECT_STREQ(sink.winds[1].source, "mwv_apparent");
  EXPECT_NEAR(sink.winds[1].from_deg,
              std::atan2(-we, -wn) / rad + 360.0 * (std::atan2(-we, -wn) < 0), 1e-6);
  EXPECT_NEAR(sink.winds[1].speed_m_s, std::hypot(wn, we), 1e-9);
  // The same wind read both ways agrees to a few degrees (the instrument's own true wind is
  // water-referenced and leeway is in both): 178.2 (T), 185.5 (R made true), 186.8 (T).
  EXPECT_NEAR(std::remainder(sink.winds[1].from_deg - sink.winds[0].from_deg, 360.0), 0.0, 10.0);
  EXPECT_NEAR(sink.winds[2].from_deg, std::fmod(318.0 + 228.83, 360.0), 1e-9);
}

TEST(ImportNmeaLog, WindDirectionsFromMwdAndInvalidReadingsSkipped) {
  const std::string log =
      s("GPRMC,105640.00,A,3930.0000,N,00230.0000,E,5.0,010.0,080226,,,A") + "\n" +
      s("WIMWD,250.5,T,248.0,M,14.0,N,7.2,M") + "\n" + s("WIMWV,045,T,12.0,N,A") + "\n" +
      s("GPRMC,105641.00,A,3930.0010,N,00230.0010,E,5.0,010.0,080226,,,A") + "\n" +
      s("WIMWV,045,T,12.0,N,V") + "\n" +        // status V: not valid
      s("WIMWD,,T,248.0,M,14.0,N,,M") + "\n" +  // magnetic only, and no declination given
      s("GPRMC,105642.00,A,3930.0020,N,00230.0020,E,5.0,010.0,080226,,,A") + "\n" +
      s("WIMWD,,T,248.0,M,14.0,N,,M") + "\n";
  Collect sink;
  const auto r = run(Format::kNmea, log, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.winds.size(), 1u);
  EXPECT_STREQ(sink.winds[0].source, "mwd");  // MWD outranks the MWV of its epoch
  EXPECT_DOUBLE_EQ(sink.winds[0].from_deg, 250.5);
  EXPECT_DOUBLE_EQ(sink.winds[0].speed_m_s, 7.2);  // m/s preferred to knots
  EXPECT_EQ(r.skipped, 3u);
  // With the declination, the magnetic direction is made true (knots when no m/s).
  ImportOptions o;
  o.declination_deg = 2.5;
  Collect with_decl;
  ASSERT_EQ(run(Format::kNmea, log, with_decl, o).status, ParseStatus::kOk);
  ASSERT_EQ(with_decl.winds.size(), 3u);
  EXPECT_DOUBLE_EQ(with_decl.winds[2].from_deg, 250.5);
  EXPECT_NEAR(with_decl.winds[2].speed_m_s, 14.0 * 1852.0 / 3600.0, 1e-9);
}

}  // namespace
}  // namespace telltale::shore::import
