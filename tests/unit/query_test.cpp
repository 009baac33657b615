#include "query.hpp"

#include <gtest/gtest.h>

namespace telltale::shore {
namespace {

TEST(ParseTime, IsoAndEpochAgree) {
  // 2026-11-22T10:00:00Z = 1795341600 s since 1970 (checked with `date -u -d ... +%s`).
  const std::uint64_t expected = 1795341600ULL * 1000000000ULL;
  EXPECT_EQ(parse_time_ns("2026-11-22T10:00:00Z"), expected);
  EXPECT_EQ(parse_time_ns("2026-11-22T10:00:00"), expected);
  EXPECT_EQ(parse_time_ns("2026-11-22T12:30:00+02:30"), expected);
  EXPECT_EQ(parse_time_ns("2026-11-22T10:00"), expected);
  EXPECT_EQ(parse_time_ns("1795341600"), expected);
  EXPECT_EQ(parse_time_ns("1795341600.25"), expected + 250000000ULL);
  EXPECT_EQ(parse_time_ns("2026-11-22T10:00:00.123456789Z"), expected + 123456789ULL);
  EXPECT_EQ(parse_time_ns("1970-01-01T00:00:00Z"), 0u);
  EXPECT_EQ(parse_time_ns("2024-02-29T00:00:00Z"), 1709164800ULL * 1000000000ULL);
}

TEST(ParseTime, RejectsEverythingElse) {
  for (const char* bad : {"", "nan", "NaN", "inf", "-1", "1e9", "0x10", "2026-13-01T00:00:00Z",
                          "2026-02-30T00:00:00Z", "2023-02-29T00:00:00Z", "2026-11-22T24:00:00Z",
                          "2026-11-22", "tomorrow", "2026-11-22T10:00:00Zjunk", "1795341600;DROP",
                          "' OR 1=1 --", "99999999999999999999", "3000000000000"}) {
    EXPECT_FALSE(parse_time_ns(bad)) << bad;
  }
}

TEST(ParseInt, Strict) {
  EXPECT_EQ(parse_int("42", 1, 100), 42);
  EXPECT_FALSE(parse_int("0", 1, 100));
  EXPECT_FALSE(parse_int("101", 1, 100));
  EXPECT_FALSE(parse_int("4x", 1, 100));
  EXPECT_FALSE(parse_int("", 1, 100));
  EXPECT_FALSE(parse_int("nan", 1, 100));
  EXPECT_FALSE(parse_int("99999999999999999999999", 1, INT64_MAX));
}

TEST(ValidId, Charset) {
  EXPECT_TRUE(valid_id("ILCA-7_b"));
  EXPECT_FALSE(valid_id(""));
  EXPECT_FALSE(valid_id(std::string(33, 'a')));
  EXPECT_FALSE(valid_id("a'b"));
  EXPECT_FALSE(valid_id("a b"));
  EXPECT_FALSE(valid_id("../etc"));
}

TEST(ParseRange, Order) {
  const std::string a = "100", b = "200";
  EXPECT_EQ(parse_range(&a, &b).from_ns, 100000000000ULL);
  EXPECT_THROW((void)parse_range(&b, &a), HttpError);
  const std::string bad = "x";
  try {
    (void)parse_range(&bad, nullptr);
    FAIL();
  } catch (const HttpError& e) {
    EXPECT_EQ(e.status(), 400);
  }
  const auto all = parse_range(nullptr, nullptr);
  EXPECT_EQ(all.from_ns, 0u);
  EXPECT_EQ(all.to_ns, UINT64_MAX);
}

}  // namespace
}  // namespace telltale::shore
