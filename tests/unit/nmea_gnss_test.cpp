// NMEA 0183 GNSS sentences and epochs (boat_node/sensors/nmea_gnss.hpp).
#include "nmea_gnss.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

using namespace telltale::sensors;

namespace {

std::string sentence(const std::string& body) {
  unsigned x = 0;
  for (char c : body) x ^= static_cast<unsigned char>(c);
  char cs[4];
  std::snprintf(cs, sizeof cs, "%02X", x);
  return "$" + body + "*" + cs;
}

NmeaGnss ok(const std::string& body) {
  const auto r = parse_nmea_gnss(sentence(body));
  EXPECT_EQ(r.status, NmeaStatus::kOk) << body << ": " << nmea_status_name(r.status);
  return r.gnss;
}

NmeaStatus status_of(const std::string& line) { return parse_nmea_gnss(line).status; }

}  // namespace

TEST(NmeaGnss, RmcGivesPositionSpeedCourseDateAndTime) {
  const auto g = ok("GPRMC,123519.50,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W,A");
  EXPECT_EQ(g.sentence, GnssSentence::kRmc);
  EXPECT_NEAR(g.time_of_day_s, 12 * 3600 + 35 * 60 + 19.5, 1e-9);
  EXPECT_NEAR(g.lat_deg, 48 + 7.038 / 60, 1e-12);
  EXPECT_NEAR(g.lon_deg, 11 + 31.0 / 60, 1e-12);
  EXPECT_NEAR(g.sog_m_s, 22.4 * 1852 / 3600, 1e-9);
  EXPECT_DOUBLE_EQ(g.cog_deg, 84.4);
  EXPECT_EQ(g.date_ddmmyy, 230394);
  EXPECT_FALSE(g.no_fix);
}

TEST(NmeaGnss, SouthAndWestAreNegativeFromAnyTalker) {
  for (const char* talker : {"GP", "GN", "GL", "GA", "GB", "II"}) {
    const auto g =
        ok(std::string(talker) + "RMC,000000,A,3352.500,S,15112.000,W,5.0,270.0,010126,,,D");
    EXPECT_NEAR(g.lat_deg, -(33 + 52.5 / 60), 1e-12) << talker;
    EXPECT_NEAR(g.lon_deg, -(151 + 12.0 / 60), 1e-12) << talker;
    EXPECT_TRUE(g.differential);
  }
}

TEST(NmeaGnss, GgaGsaVtgGnsCarryTheirFields) {
  const auto gga = ok("GNGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,");
  EXPECT_EQ(gga.gga_quality, 1);
  EXPECT_EQ(gga.satellites, 8);
  EXPECT_DOUBLE_EQ(gga.hdop, 1.03);
  EXPECT_NEAR(gga.lon_deg, -(6 + 30.3372 / 60), 1e-12);
  const auto gsa = ok("GNGSA,A,2,01,02,03,,,,,,,,,,2.5,1.3,2.1");
  EXPECT_EQ(gsa.gsa_mode, 2);
  EXPECT_DOUBLE_EQ(gsa.hdop, 1.3);
  const auto vtg = ok("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K,A");
  EXPECT_DOUBLE_EQ(vtg.cog_deg, 54.7);
  EXPECT_NEAR(vtg.sog_m_s, 5.5 * 1852 / 3600, 1e-9);
  const auto vtg_kmh = ok("GPVTG,054.7,T,,M,,N,036.0,K,A");
  EXPECT_NEAR(vtg_kmh.sog_m_s, 10.0, 1e-9);
  const auto gns = ok("GNGNS,014035.00,4332.69262,S,17235.48549,E,RAN,13,0.9,25.2,-3.0,,");
  EXPECT_TRUE(gns.differential);
  EXPECT_FALSE(gns.no_fix);
  EXPECT_EQ(gns.satellites, 13);
  const auto gns_none = ok("GNGNS,014035.00,,,,,NN,00,,,,,");
  EXPECT_TRUE(gns_none.no_fix);
  EXPECT_TRUE(std::isnan(gns_none.lat_deg));
}

TEST(NmeaGnss, NoFixIsParsedAndSaysSo) {
  EXPECT_TRUE(ok("GPRMC,123519,V,,,,,,,230394,,,N").no_fix);
  EXPECT_TRUE(ok("GPGGA,123519,,,,,0,00,,,M,,M,,").no_fix);
  EXPECT_TRUE(ok("GPGSA,A,1,,,,,,,,,,,,,,,").no_fix);
  EXPECT_TRUE(ok("GPGGA,123519,4807.038,N,01131.000,E,6,04,2.0,1,M,1,M,,").no_fix)
      << "quality 6 is dead reckoning, not a measured fix";
}

TEST(NmeaGnss, MalformedAndHostileSentencesAreRefusedWithTheirReason) {
  EXPECT_EQ(status_of("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"),
            NmeaStatus::kMissingChecksum);
  EXPECT_EQ(status_of("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*00"),
            NmeaStatus::kBadChecksum);
  EXPECT_EQ(status_of(sentence("GPGSV,3,1,11,03,03,111,00")), NmeaStatus::kUnsupported);
  for (const char* body : {
           "GPRMC,123519,A,4807.038,N,01131.000,E,nan,084.4,230394,,,A",    // NaN speed
           "GPRMC,123519,A,4807.038,N,01131.000,E,inf,084.4,230394,,,A",    // Inf
           "GPRMC,123519,A,4867.038,N,01131.000,E,1.0,084.4,230394,,,A",    // 67 minutes
           "GPRMC,123519,A,9107.038,N,01131.000,E,1.0,084.4,230394,,,A",    // 91 deg N
           "GPRMC,123519,A,4807.038,X,01131.000,E,1.0,084.4,230394,,,A",    // hemisphere X
           "GPRMC,123519,A,4807.038,N,,,1.0,084.4,230394,,,A",              // lat without lon
           "GPRMC,123519,A,4807.038,N,01131.000,E,-1.0,084.4,230394,,,A",   // negative speed
           "GPRMC,123519,A,4807.038,N,01131.000,E,1.0,361.0,230394,,,A",    // course > 360
           "GPRMC,126519,A,4807.038,N,01131.000,E,1.0,084.4,230394,,,A",    // 65 minutes
           "GPRMC,123519,A,4807.038,N,01131.000,E,1.0,084.4,320394,,,A",    // day 32
           "GPRMC,123519,Q,4807.038,N,01131.000,E,1.0,084.4,230394,,,A",    // status Q
           "GPRMC,123519,A,4807.038,N",                                     // cut short
           "GPGGA,123519,4807.038,N,01131.000,E,9,08,0.9,1,M,1,M,,",        // quality 9
           "GPGGA,123519,4807.038,N,01131.000,E,1,8.5,0.9,1,M,1,M,,",       // 8.5 satellites
           "GPGSA,A,4,,,,,,,,,,,,,,,",                                       // mode 4
           "GPVTG,054.7,T,034.4,M,005.5,X,010.2,K,A",                       // unit X
       }) {
    EXPECT_EQ(status_of(sentence(body)), NmeaStatus::kMalformed) << body;
  }
}

TEST(NmeaGnss, RandomBytesNeverParseAsAFix) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 20000; ++i) {
    std::string line = "$GPRMC,";
    const int n = byte(rng) % 90;
    for (int k = 0; k < n; ++k) line.push_back(static_cast<char>(byte(rng)));
    const auto r = parse_nmea_gnss(line);
    EXPECT_NE(r.status, NmeaStatus::kOk) << line;  // no checksum matches by chance
  }
}

TEST(GnssEpochs, OneEpochFromItsSentencesEmittedWhenTheNextOpensOrTheLineIsQuiet) {
  GnssEpochAssembler a(0.025);
  const auto add = [&](const std::string& body, double t) {
    return a.add(parse_nmea_gnss(sentence(body)).gnss, t);
  };
  EXPECT_FALSE(add("GNRMC,120000.00,A,5420.640,N,01011.400,E,10.0,045.0,021226,,,A", 0.000));
  EXPECT_FALSE(add("GNVTG,046.0,T,,M,9.0,N,,K,A", 0.002));  // RMC's speed wins
  EXPECT_FALSE(add("GNGGA,120000.00,5420.640,N,01011.400,E,1,11,0.7,5,M,40,M,,", 0.004));
  EXPECT_FALSE(add("GNGSA,A,3,01,02,03,04,,,,,,,,,1.2,0.7,1.0", 0.006));
  EXPECT_FALSE(a.flush_if_quiet(0.020));
  const auto r = a.flush_if_quiet(0.040);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->fix, GnssFixKind::k3D);
  EXPECT_NEAR(r->lat_deg, 54 + 20.64 / 60, 1e-12);
  EXPECT_NEAR(r->sog_m_s, 10.0 * 1852 / 3600, 1e-9);
  EXPECT_DOUBLE_EQ(r->cog_deg, 45.0);
  EXPECT_EQ(r->satellites, 11);
  EXPECT_DOUBLE_EQ(r->hdop, 0.7);
  EXPECT_EQ(r->date_ddmmyy, 21226);
  // A new time of day closes the open epoch at once.
  EXPECT_FALSE(add("GNGGA,120000.10,5420.641,N,01011.401,E,1,11,0.7,5,M,40,M,,", 1.0));
  const auto next = add("GNGGA,120000.20,5420.642,N,01011.402,E,0,00,,,M,,M,,", 1.1);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->fix, GnssFixKind::k3D);
  EXPECT_TRUE(std::isnan(next->sog_m_s)) << "GGA alone gives no speed";
  const auto none = a.flush_if_quiet(2.0);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->fix, GnssFixKind::kNone);
  EXPECT_TRUE(std::isnan(none->lat_deg));
}

TEST(GnssEpochs, A2DFixAndADifferentialOneAreToldApart) {
  GnssEpochAssembler a;
  a.add(parse_nmea_gnss(sentence("GPGGA,000001,4807.038,N,01131.000,E,1,03,2.0,,M,,M,,")).gnss, 0);
  a.add(parse_nmea_gnss(sentence("GPGSA,A,2,01,02,03,,,,,,,,,,3.0,2.0,2.2")).gnss, 0);
  EXPECT_EQ(a.flush_if_quiet(1)->fix, GnssFixKind::k2D);
  a.add(parse_nmea_gnss(sentence("GPGGA,000002,4807.038,N,01131.000,E,2,09,0.8,,M,,M,,")).gnss, 2);
  EXPECT_EQ(a.flush_if_quiet(3)->fix, GnssFixKind::kDgnss);
}
