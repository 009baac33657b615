#include "import_store.hpp"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "temp_dir_test.hpp"
#include "tier_check.hpp"

namespace telltale::shore::import {
namespace {

constexpr std::uint64_t kSecond = 1000000000ULL;
constexpr std::uint64_t kT0s = 1795300000ULL;  // 2026-11-22T... UTC

/// An Atlas CSV (new dialect, UTC offset +01:00) of `n` rows at `hz` from kT0s + start_s.
std::string atlas_csv(double start_s, std::size_t n, double hz) {
  std::string out = "timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\r\n";
  char line[160];
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(kT0s) + start_s + static_cast<double>(i) / hz + 3600.0;
    const auto secs = static_cast<std::time_t>(std::floor(t));
    const int ms = static_cast<int>(std::lround((t - std::floor(t)) * 1000.0));
    std::tm tm{};
    gmtime_r(&secs, &tm);
    const double a = static_cast<double>(i) * 0.01;
    std::snprintf(line, sizeof line,
                  "%04d-%02d-%02dT%02d:%02d:%02d.%03d+0100,%.7f,%.7f,%.2f,%.1f,%.1f,%.1f,%.1f\r\n",
                  tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                  ms, 39.5 + 1e-5 * std::sin(a), 2.5 + 1e-5 * std::cos(a), 6.0 + std::sin(a),
                  std::fmod(90.0 + 10.0 * a, 360.0), std::fmod(92.0 + 10.0 * a, 360.0),
                  15.0 * std::sin(a), 6.0 + std::cos(a));
    out += line;
  }
  return out;
}

class ImportStoreTest : public test::TempDirTest {
 protected:
  ImportStoreTest() : TempDirTest("telltale_import_") {}
  StoreConfig config() const {
    StoreConfig c;
    c.path = (dir_ / "s.db").string();
    c.commit_interval = std::chrono::milliseconds(20);
    return c;
  }
  std::string write(const std::string& name, const std::string& bytes) const {
    const auto p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  ImportRecord import(ImportStore& imports, const std::string& path, const std::string& boat = "ILCA-1") {
    ImportRequest req;
    req.boat_id = boat;
    req.file_name = std::filesystem::path(path).filename().string();
    req.path = path;
    const auto id = imports.begin(boat, req.file_name, std::filesystem::file_size(path));
    return imports.run(id, req);
  }
  /// Counts rows straight from the SQLite file.
  std::int64_t rows(const std::string& sql) const {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(config().path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* st = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr), SQLITE_OK) << sql;
    std::int64_t n = -1;
    if (sqlite3_step(st) == SQLITE_ROW) n = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    return n;
  }
};

TEST_F(ImportStoreTest, AtlasCsvBecomesASessionWithSamplesAndFixes) {
  Store store(config());
  ImportStore imports(store);
  const auto r = import(imports, write("a.csv", atlas_csv(0, 600, 2.0)));
  ASSERT_EQ(r.state, "done") << r.error;
  EXPECT_EQ(r.format, "vakaros_csv");
  EXPECT_EQ(r.points, 600u);
  EXPECT_EQ(r.samples_added, 600u);
  EXPECT_EQ(r.fixes_added, 600u);
  EXPECT_EQ(r.sha256.size(), 64u);
  ASSERT_EQ(r.sessions.size(), 1u);
  const auto s = store.session(r.sessions[0]);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->boat_id, "ILCA-1");
  EXPECT_EQ(s->start_ns, kT0s * kSecond);
  EXPECT_EQ(s->end_ns, kT0s * kSecond + 2995 * kSecond / 10);
  EXPECT_EQ(s->samples, 600);
  // The review routes read it like live data.
  EXPECT_EQ(store.track("ILCA-1", 0, UINT64_MAX, 0).size(), 600u);
  EXPECT_EQ(store.count("ILCA-1"), 600);
  const auto again = imports.get(r.id);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->state, "done");
  EXPECT_EQ(again->sessions, r.sessions);
}

TEST_F(ImportStoreTest, SameFileAgainChangesNothing) {
  Store store(config());
  ImportStore imports(store);
  const auto path = write("a.csv", atlas_csv(0, 100, 2.0));
  const auto first = import(imports, path);
  ASSERT_EQ(first.state, "done") << first.error;
  const auto sessions_before = rows("SELECT COUNT(*) FROM sessions");
  const auto second = import(imports, path);
  EXPECT_EQ(second.state, "done") << second.error;
  EXPECT_EQ(second.duplicate_of, first.id);
  EXPECT_EQ(second.sessions, first.sessions);
  EXPECT_EQ(second.samples_added, 0u);
  EXPECT_EQ(rows("SELECT COUNT(*) FROM sessions"), sessions_before);
  EXPECT_EQ(rows("SELECT COUNT(*) FROM attitude"), 100);
  EXPECT_EQ(rows("SELECT samples FROM sessions"), 100);
  // Another boat's copy is that boat's data.
  EXPECT_EQ(import(imports, path, "ILCA-2").samples_added, 100u);
}

TEST_F(ImportStoreTest, OverlapWithLiveDataMergesByTime) {
  Store store(config());
  // Live: 60 s at 1 Hz from t0 + 100 s, one sample at a time the file also holds.
  for (std::uint64_t i = 0; i < 60; ++i) {
    AttitudeSample s;
    s.boat_id = "ILCA-1";
    s.boot_id = 9;
    s.seq = i + 1;
    s.t_utc_ns = (kT0s + 100 + i) * kSecond + (i == 0 ? 0 : kSecond / 4);
    s.heel_deg = 3;
    s.pitch_deg = 1;
    s.heading_deg = std::nan("");
    store.enqueue(s);
  }
  store.flush();
  ASSERT_EQ(store.sessions("ILCA-1", 0, UINT64_MAX).size(), 1u);
  ImportStore imports(store);
  // The file: t0 .. t0 + 300 s at 2 Hz, through the live minute.
  const auto r = import(imports, write("a.csv", atlas_csv(0, 600, 2.0)));
  ASSERT_EQ(r.state, "done") << r.error;
  EXPECT_EQ(r.samples_added, 599u);  // t0 + 100 s was already stored live
  const auto sessions = store.sessions("ILCA-1", 0, UINT64_MAX);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].samples, 60 + 599);
  EXPECT_EQ(rows("SELECT COUNT(*) FROM attitude"), 60 + 599);
  EXPECT_EQ(rows("SELECT heel_deg FROM attitude WHERE t_utc_ns = " +
                 std::to_string((kT0s + 100) * kSecond)),
            3);  // the live sample kept
  expect_tiers_hold(store, "ILCA-1");  // the file's buckets merged into the live minute's
  // Live data after the import still extends that session.
  AttitudeSample later;
  later.boat_id = "ILCA-1";
  later.boot_id = 9;
  later.seq = 61;
  later.t_utc_ns = (kT0s + 310) * kSecond;
  later.heading_deg = std::nan("");
  store.enqueue(later);
  store.flush();
  EXPECT_EQ(store.sessions("ILCA-1", 0, UINT64_MAX).size(), 1u);
}

TEST_F(ImportStoreTest, PauseLongerThanTheGapSplitsSessions) {
  Store store(config());
  ImportStore imports(store);
  std::string csv = atlas_csv(0, 100, 2.0);
  const std::string later = atlas_csv(600, 100, 2.0);
  csv += later.substr(later.find('\n') + 1);
  const auto r = import(imports, write("a.csv", csv));
  ASSERT_EQ(r.state, "done") << r.error;
  EXPECT_EQ(r.sessions.size(), 2u);
}

TEST_F(ImportStoreTest, BrokenFileStoresNothing) {
  Store store(config());
  ImportStore imports(store);
  std::string csv = atlas_csv(0, 100, 2.0);
  csv.resize(csv.size() - 30);  // the last row cut
  const auto r = import(imports, write("a.csv", csv));
  EXPECT_EQ(r.state, "failed");
  EXPECT_NE(r.error.find("line 101"), std::string::npos) << r.error;
  EXPECT_EQ(rows("SELECT COUNT(*) FROM attitude"), 0);
  EXPECT_EQ(rows("SELECT COUNT(*) FROM fixes"), 0);
  EXPECT_EQ(rows("SELECT COUNT(*) FROM sessions"), 0);
  const auto again = imports.get(r.id);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->state, "failed");
  EXPECT_EQ(again->error, r.error);
  // Not a log at all.
  const auto junk = import(imports, write("junk.bin", "hello\nworld\n"));
  EXPECT_EQ(junk.state, "failed");
  EXPECT_NE(junk.error.find("none of the formats"), std::string::npos) << junk.error;
}

TEST_F(ImportStoreTest, CutBinaryLogKeepsItsPrefixMarkedPartial) {
  Store store(config());
  ImportStore imports(store);
  std::string vkx;
  vkx.push_back(static_cast<char>(0xFF));
  vkx.append(7, '\x05');
  for (int i = 0; i < 10; ++i) {
    vkx.push_back('\x02');
    const std::uint64_t ms = (kT0s + static_cast<std::uint64_t>(i)) * 1000;
    for (int b = 0; b < 8; ++b) vkx.push_back(static_cast<char>(ms >> (8 * b)));
    const std::int32_t lat = 395000000, lon = 25000000;
    for (int b = 0; b < 4; ++b) vkx.push_back(static_cast<char>(lat >> (8 * b)));
    for (int b = 0; b < 4; ++b) vkx.push_back(static_cast<char>(lon >> (8 * b)));
    vkx.append(12, '\0');  // SOG, COG, altitude 0
    const float w = 1.0f;
    char wb[4];
    std::memcpy(wb, &w, 4);
    vkx.append(wb, 4);
    vkx.append(12, '\0');
  }
  vkx.push_back('\x02');
  vkx.append(10, '\x01');  // cut
  const auto r = import(imports, write("a.vkx", vkx));
  ASSERT_EQ(r.state, "done") << r.error;
  EXPECT_EQ(r.format, "vkx");
  EXPECT_EQ(r.points, 10u);
  EXPECT_NE(r.partial.find("byte offset 458"), std::string::npos) << r.partial;
  EXPECT_EQ(rows("SELECT COUNT(*) FROM fixes"), 10);
  EXPECT_EQ(imports.get(r.id)->partial, r.partial);
}

TEST_F(ImportStoreTest, FourHourAtlasCsvAtTwoHertz) {
  Store store(config());
  ImportStore imports(store);
  const auto path = write("long.csv", atlas_csv(0, 4 * 3600 * 2, 2.0));
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = import(imports, path);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.state, "done") << r.error;
  EXPECT_EQ(r.points, 28800u);
  // 15 300 tier buckets: the fold is merged several times during the import.
  expect_tiers_hold(store, "ILCA-1");
  std::printf("4 h at 2 Hz (%ju bytes, 28800 rows): imported in %.3f s\n",
              static_cast<std::uintmax_t>(std::filesystem::file_size(path)), s);
  EXPECT_LT(s, 5.0);  // target 1 s on an idle core; the bound leaves room for a loaded machine
}

}  // namespace
}  // namespace telltale::shore::import
