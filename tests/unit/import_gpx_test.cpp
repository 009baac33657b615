#include <gtest/gtest.h>

#include <cmath>

#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

constexpr std::uint64_t kT0 = 1770548200ULL * 1000000000ULL;

TEST(ImportGpx, Gpx11WithGarminTrackPointExtension) {
  const std::string gpx = R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- exported > by a watch -->
<gpx version="1.1" creator="Garmin Forerunner 965" xmlns="http://www.topografix.com/GPX/1/1"
     xmlns:gpxtpx="http://www.garmin.com/xmlschemas/TrackPointExtension/v2">
 <trk><name>Race 1</name><trkseg>
  <trkpt lat="39.5" lon='2.5'><ele>1.0</ele><time>2026-02-08T10:56:40Z</time>
   <extensions><gpxtpx:TrackPointExtension><gpxtpx:speed>3.25</gpxtpx:speed>
   <gpxtpx:course>181.5</gpxtpx:course></gpxtpx:TrackPointExtension></extensions></trkpt>
  <trkpt lat="39.50001" lon="2.50001"><time>2026-02-08T11:56:41.500+01:00</time></trkpt>
 </trkseg></trk>
</gpx>
)";
  Collect sink;
  const auto r = run(Format::kGpx, gpx, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.device_name, "Garmin Forerunner 965");
  EXPECT_EQ(sink.points[0].t_utc_ns, kT0);
  EXPECT_DOUBLE_EQ(sink.points[0].sog_m_s, 3.25);
  EXPECT_DOUBLE_EQ(sink.points[0].cog_deg, 181.5);
  EXPECT_EQ(sink.points[1].t_utc_ns, kT0 + 1500000000ULL);
  EXPECT_TRUE(std::isnan(sink.points[1].sog_m_s));
}

TEST(ImportGpx, Gpx10SpeedAndCourseAndTelltaleExtensions) {
  const std::string gpx =
      "<gpx version=\"1.0\"><trk><trkseg><trkpt lat=\"-33.9\" lon=\"151.2\">"
      "<time>2026-02-08T10:56:40Z</time><course>90</course><speed>4.5</speed>"
      "<extensions><tt:heel_deg>12.5</tt:heel_deg><tt:pitch_deg>-1.5</tt:pitch_deg>"
      "</extensions></trkpt></trkseg></trk></gpx>";
  Collect sink;
  const auto r = run(Format::kGpx, gpx, sink);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 1u);
  EXPECT_DOUBLE_EQ(sink.points[0].sog_m_s, 4.5);
  EXPECT_DOUBLE_EQ(sink.points[0].cog_deg, 90.0);
  EXPECT_DOUBLE_EQ(sink.points[0].heel_deg, 12.5);
  EXPECT_DOUBLE_EQ(sink.points[0].pitch_deg, -1.5);
}

TEST(ImportGpx, BrokenFilesNameTheLine) {
  const std::string head = "<gpx version=\"1.1\">\n<trk><trkseg>\n";
  const std::string pt = "<trkpt lat=\"1\" lon=\"2\"><time>2026-02-08T10:56:40Z</time></trkpt>\n";
  Collect sink;
  auto r = run(Format::kGpx, head + pt + "<trkpt lat=\"1\" lon=\"2\"><time>2026-02", sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  EXPECT_NE(r.message.find("line 4"), std::string::npos) << r.message;
  r = run(Format::kGpx, head + pt, sink);
  EXPECT_EQ(r.status, ParseStatus::kError);
  EXPECT_NE(r.message.find("before </gpx>"), std::string::npos) << r.message;
  r = run(Format::kGpx, head + "<trkpt lat=\"95\" lon=\"2\"></trkpt></trkseg></trk></gpx>", sink);
  EXPECT_EQ(r.message.rfind("line 3: track point without a valid", 0), 0u) << r.message;
  r = run(Format::kGpx, head + "<trkpt lat=\"1\" lon=\"2\"><time>soon</time></trkpt>", sink);
  EXPECT_NE(r.message.find("not an ISO 8601 time"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace telltale::shore::import
