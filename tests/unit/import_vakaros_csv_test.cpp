#include <gtest/gtest.h>

#include <cmath>

#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using test::Collect;
using test::run;

// 2026-02-08T10:56:40.049Z
constexpr std::uint64_t kT0 = 1770548200049000000ULL;

TEST(ImportVakarosCsv, NewDialectWithOffsetCrlfBomAndPaddedRows) {
  const std::string csv =
      "\xEF\xBB\xBFtimestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\r\n"
      "2026-02-08T11:56:40.049+0100,39.5,2.5,10.0,266.1,245.8,-1.8,7.7\r\n"
      ",,,,,,,\r\n"
      "\r\n"
      "2026-02-08T11:56:40.549+01:00,39.5000100,2.5000200,,,,12.5,5.0,,,\r\n";
  Collect sink;
  const auto r = run(Format::kVakarosCsv, csv, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(r.skipped, 2u);
  EXPECT_EQ(sink.points[0].t_utc_ns, kT0);
  EXPECT_EQ(sink.points[1].t_utc_ns, kT0 + 500000000ULL);
  EXPECT_NEAR(sink.points[0].sog_m_s, 10.0 * 1852.0 / 3600.0, 1e-9);
  EXPECT_DOUBLE_EQ(sink.points[0].cog_deg, 266.1);
  EXPECT_DOUBLE_EQ(sink.points[0].heading_deg, 245.8);
  EXPECT_DOUBLE_EQ(sink.points[0].heel_deg, -1.8);
  EXPECT_DOUBLE_EQ(sink.points[0].pitch_deg, 7.7);
  EXPECT_TRUE(std::isnan(sink.points[1].sog_m_s));
  EXPECT_DOUBLE_EQ(sink.points[1].heel_deg, 12.5);
}

TEST(ImportVakarosCsv, OldDialectNeedsTheTimeZone) {
  const std::string csv =
      "timestamp,latitude,longitude,sog_kts,cog,hdg_true,roll,pitch,load_GDF2,load_GDF1\n"
      "2026-02-08T11:56:40.049,41.7387700,12.2457483,0.000,113.1,125.4,-1.7,4.6,1.40,141.20\n";
  Collect sink;
  const auto refused = run(Format::kVakarosCsv, csv, sink);
  EXPECT_EQ(refused.status, ParseStatus::kError);
  EXPECT_NE(refused.message.find("line 2"), std::string::npos) << refused.message;
  EXPECT_NE(refused.message.find("time zone"), std::string::npos) << refused.message;

  ImportOptions o;
  o.utc_offset_s = 3600;
  o.pitch_offset_deg = 6.0;
  Collect sink2;
  const auto r = run(Format::kVakarosCsv, csv, sink2, o);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink2.points.size(), 1u);
  EXPECT_EQ(sink2.points[0].t_utc_ns, kT0);
  EXPECT_DOUBLE_EQ(sink2.points[0].heel_deg, -1.7);
  EXPECT_NEAR(sink2.points[0].pitch_deg, 4.6 - 6.0, 1e-12);
}

TEST(ImportVakarosCsv, BadRowsNameTheirLine) {
  const std::string head = "timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\n";
  const std::string good = "2026-02-08T11:56:40.049+0100,39.5,2.5,1,2,3,4,5\n";
  Collect sink;
  auto r = run(Format::kVakarosCsv, head + good + "2026-02-08T11:56:41.049+0100,9x,2.5,1,2,3,4,5\n",
               sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  EXPECT_EQ(r.message.rfind("line 3: latitude", 0), 0u) << r.message;
  r = run(Format::kVakarosCsv, head + good + "2026-02-08T11:56:41.049+0100,91,2.5,1,2,3,4,5\n", sink);
  EXPECT_NE(r.message.find("out of range"), std::string::npos) << r.message;
  // Cut short in the middle of a row.
  r = run(Format::kVakarosCsv, head + good + "2026-02-08T11:56:41.049+0100,39.5", sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  EXPECT_NE(r.message.find("line 3"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("cut short"), std::string::npos) << r.message;
  r = run(Format::kVakarosCsv, "lat,lon\n1,2\n", sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  r = run(Format::kVakarosCsv, head, sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
}

}  // namespace
}  // namespace telltale::shore::import
