#include <gtest/gtest.h>

#include "import_support.hpp"
#include "time_zone.hpp"

namespace telltale::shore::import {
namespace {

using test::Collect;
using test::run;

constexpr std::int64_t kH = 3600;

std::int64_t local(int y, int mo, int d, int h, int mi) {
  return *days_from_civil(y, mo, d) * 86400 + h * kH + mi * 60;
}

TEST(ImportTimeZone, SummerWinterAndTheChanges) {
  const auto z = TimeZone::load("Europe/Madrid");
  ASSERT_TRUE(z) << "tzdata (/usr/share/zoneinfo) is needed";
  EXPECT_EQ(z->offset_at_local(local(2026, 1, 15, 12, 0)), 1 * kH);
  EXPECT_EQ(z->offset_at_local(local(2026, 7, 1, 12, 0)), 2 * kH);
  // 2026-03-29: 02:00 local becomes 03:00. 02:30 does not exist: the offset before the change.
  EXPECT_EQ(z->offset_at_local(local(2026, 3, 29, 1, 30)), 1 * kH);
  EXPECT_EQ(z->offset_at_local(local(2026, 3, 29, 2, 30)), 1 * kH);
  EXPECT_EQ(z->offset_at_local(local(2026, 3, 29, 3, 30)), 2 * kH);
  // 2026-10-25: 03:00 local becomes 02:00. 02:30 happens twice: the first (summer) one.
  EXPECT_EQ(z->offset_at_local(local(2026, 10, 25, 2, 30)), 2 * kH);
  EXPECT_EQ(z->offset_at_local(local(2026, 10, 25, 3, 30)), 1 * kH);
  const auto ny = TimeZone::load("America/New_York");
  ASSERT_TRUE(ny);
  EXPECT_EQ(ny->offset_at_local(local(2026, 7, 4, 12, 0)), -4 * kH);
  EXPECT_EQ(TimeZone::load("UTC")->offset_at_local(local(2026, 7, 4, 12, 0)), 0);
}

TEST(ImportTimeZone, UnknownOrHostileNames) {
  EXPECT_FALSE(TimeZone::load("Mars/Olympus"));
  EXPECT_FALSE(TimeZone::load("../../etc/passwd"));
  EXPECT_FALSE(TimeZone::load("/etc/localtime"));
  EXPECT_FALSE(TimeZone::load(""));
  EXPECT_FALSE(TimeZone::load("Europe"));  // a folder
}

TEST(ImportTimeZone, OldAtlasDialectInANamedZone) {
  const std::string csv =
      "timestamp,latitude,longitude,sog_kts,cog,hdg_true,roll,pitch\n"
      "2026-07-01T12:00:00.000,41.7,12.2,1,2,3,4,5\n"
      "2026-01-15T12:00:00.500,41.7,12.2,1,2,3,4,5\n";
  const auto z = TimeZone::load("Europe/Rome");
  ASSERT_TRUE(z);
  ImportOptions o;
  o.local_offset_s = [&](std::int64_t s) { return z->offset_at_local(s); };
  Collect sink;
  const auto r = run(Format::kVakarosCsv, csv, sink, o);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.message;
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.points[0].t_utc_ns,
            static_cast<std::uint64_t>(local(2026, 7, 1, 10, 0)) * 1000000000ULL);
  EXPECT_EQ(sink.points[1].t_utc_ns,
            static_cast<std::uint64_t>(local(2026, 1, 15, 11, 0)) * 1000000000ULL + 500000000ULL);
}

}  // namespace
}  // namespace telltale::shore::import
