// The field tables: the store writes and reads back every field of them, a
// database made before a field existed gets its column, the columns of schema version 3 stay as
// they were, and openapi.json describes exactly the fields the exports write.
#include "sample_fields.hpp"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "json_views.hpp"
#include "openapi_json.hpp"
#include "temp_dir_test.hpp"

namespace telltale::shore {
namespace {

using ordered_json = nlohmann::ordered_json;

constexpr std::uint64_t kT0 = 1795300000ULL * 1000000000ULL;

class SampleFieldsTest : public test::TempDirTest {
 protected:
  SampleFieldsTest() : TempDirTest("telltale_fields_") {}
  [[nodiscard]] StoreConfig config() const {
    StoreConfig c;
    c.path = (dir_ / "s.db").string();
    c.commit_interval = std::chrono::milliseconds(20);
    return c;
  }
};

/// A value of its own for every field: the k-th field gets k in its type (a kind of fix for
/// text, never "none", which fix_page skips).
template <class T>
void set_value(T& v, int k) {
  if constexpr (std::is_same_v<T, std::string>) {
    v = "kind" + std::to_string(k);
  } else if constexpr (std::is_floating_point_v<T>) {
    v = static_cast<T>(k) + static_cast<T>(0.5);
  } else {
    v = static_cast<T>(k);
  }
}

template <class Table, class Record>
void set_every_stored_field(const Table& table, Record& r) {
  int k = 1;
  for_each_field<kStored>(table, [&](const auto& f) { set_value(f.get(r), k++); });
}

/// The read-back fields of `got` are those of `sent`, each compared in the wider of the types.
template <class Table, class Sent, class Got>
void expect_read_back(const Table& table, const Sent& sent, const Got& got) {
  for_each_field<kRead>(table, [&](const auto& f) {
    const auto& a = f.get(sent);
    const auto& b = f.get(got);
    if constexpr (std::is_floating_point_v<std::remove_cvref_t<decltype(a)>>) {
      EXPECT_EQ(static_cast<double>(a), static_cast<double>(b)) << f.name;
    } else {
      EXPECT_EQ(a, b) << f.name;
    }
  });
}

// Given a sample and a fix with every field set, when stored and read back, then every field the
// table reads comes back as sent (a new field needs no code in the store, only its table row).
TEST_F(SampleFieldsTest, TheStoreWritesAndReadsBackEveryField) {
  AttitudeSample s;
  set_every_stored_field(kAttitudeFields, s);
  s.boat_id = "b1";
  s.t_utc_ns = kT0;
  FixSample f;
  set_every_stored_field(kFixFields, f);
  f.boat_id = "b1";
  f.t_utc_ns = kT0;
  f.boot_id = s.boot_id;
  Store store(config());
  store.enqueue(s);
  store.enqueue(f);
  store.flush();
  const auto rows = store.attitude_page("b1", 0, kT0, 10);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].t_utc_ns, kT0);
  expect_read_back(kAttitudeFields, s, rows[0]);
  const auto fixes = store.fix_page("b1", 0, kT0, 10);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].t_utc_ns, kT0);
  expect_read_back(kFixFields, f, fixes[0]);
}

/// Name, declared type, NOT NULL, default and key position of every column of a table.
std::vector<std::string> columns_of(sqlite3* db, const std::string& table) {
  sqlite3_stmt* st = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db,
                               "SELECT name, type, \"notnull\", coalesce(dflt_value, ''), pk "
                               "FROM pragma_table_info(?1)",
                               -1, &st, nullptr),
            SQLITE_OK);
  sqlite3_bind_text(st, 1, table.c_str(), -1, SQLITE_TRANSIENT);
  std::vector<std::string> out;
  while (sqlite3_step(st) == SQLITE_ROW) {
    std::string col;
    for (int c = 0; c < 5; ++c)
      col += std::string(c ? "|" : "") + reinterpret_cast<const char*>(sqlite3_column_text(st, c));
    out.push_back(col);
  }
  sqlite3_finalize(st);
  return out;
}

// The columns of schema version 3, as databases on disk have them: every one is still made, with
// its type, constraint, default and key (fields added later may only come after them).
TEST_F(SampleFieldsTest, TheTablesKeepTheColumnsOfSchemaVersion3) {
  { Store store(config()); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(config().path.c_str(), &db), SQLITE_OK);
  const std::vector<std::string> attitude = columns_of(db, "attitude");
  const std::vector<std::string> fixes = columns_of(db, "fixes");
  sqlite3_close(db);
  const std::vector<std::string> v3_attitude = {
      "boat_id|TEXT|1||1",         "t_utc_ns|INTEGER|1||2",      "seq|INTEGER|1||0",
      "heel_deg|REAL|1||0",        "pitch_deg|REAL|1||0",        "heading_deg|REAL|0||0",
      "heel_rate_deg_s|REAL|0||0", "pitch_rate_deg_s|REAL|0||0", "yaw_rate_deg_s|REAL|0||0",
      "accel_weight|REAL|0||0",    "quality|REAL|0||0",          "boot_id|INTEGER|1|0|0"};
  const std::vector<std::string> v3_fixes = {
      "boat_id|TEXT|1||1",        "t_utc_ns|INTEGER|1||2", "seq|INTEGER|1||0",
      "gnss_utc_ns|INTEGER|1||0", "lat_deg|REAL|0||0",     "lon_deg|REAL|0||0",
      "sog_m_s|REAL|0||0",        "cog_deg|REAL|0||0",     "fix|TEXT|1||0",
      "satellites|INTEGER|1||0",  "hdop|REAL|0||0",        "boot_id|INTEGER|1||0"};
  ASSERT_GE(attitude.size(), v3_attitude.size());
  ASSERT_GE(fixes.size(), v3_fixes.size());
  EXPECT_EQ(std::vector<std::string>(attitude.begin(), attitude.begin() + std::ssize(v3_attitude)),
            v3_attitude);
  EXPECT_EQ(std::vector<std::string>(fixes.begin(), fixes.begin() + std::ssize(v3_fixes)),
            v3_fixes);
}

// Given a database whose sample tables lack a field of the tables (as one made before the field
// existed), when the store opens it, then the column is added and the field is stored and read.
TEST_F(SampleFieldsTest, AColumnMissingFromAnOlderDatabaseIsAdded) {
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(config().path.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db,
                           "CREATE TABLE attitude (boat_id TEXT NOT NULL, t_utc_ns INTEGER NOT "
                           "NULL, seq INTEGER NOT NULL, heel_deg REAL NOT NULL, pitch_deg REAL "
                           "NOT NULL, heading_deg REAL, PRIMARY KEY (boat_id, t_utc_ns)) "
                           "WITHOUT ROWID;"
                           "CREATE TABLE fixes (boat_id TEXT NOT NULL, t_utc_ns INTEGER NOT NULL, "
                           "seq INTEGER NOT NULL, gnss_utc_ns INTEGER NOT NULL, lat_deg REAL, "
                           "lon_deg REAL, fix TEXT NOT NULL, satellites INTEGER NOT NULL, boot_id "
                           "INTEGER NOT NULL, PRIMARY KEY (boat_id, t_utc_ns)) WITHOUT ROWID;"
                           "INSERT INTO attitude VALUES ('b1', 1795299000000000000, 1, 5, 1, 90);",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  Store store(config());
  AttitudeSample s;
  s.boat_id = "b1";
  s.t_utc_ns = kT0;
  s.seq = 2;
  s.heel_deg = 3.0;
  s.pitch_deg = 1.0;
  s.quality = 0.5f;
  s.accel_weight = 0.25f;
  s.boot_id = 9;
  FixSample f;
  f.boat_id = "b1";
  f.t_utc_ns = kT0;
  f.fix = "3d";
  f.lat_deg = 41.0;
  f.lon_deg = 2.0;
  f.sog_m_s = 3.5;
  f.cog_deg = 180.0;
  f.hdop = 0.75;
  store.enqueue(s);
  store.enqueue(f);
  store.flush();
  const auto rows = store.attitude_page("b1", 0, kT0, 10);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_TRUE(std::isnan(rows[0].quality));  // the old row: no value
  EXPECT_EQ(rows[1].quality, 0.5);
  EXPECT_EQ(rows[1].accel_weight, 0.25);
  const auto fixes = store.fix_page("b1", 0, kT0, 10);
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].sog_m_s, 3.5);
  EXPECT_EQ(fixes[0].cog_deg, 180.0);
  EXPECT_EQ(fixes[0].hdop, 0.75);
}

/// The JSON type of a field of `Record` in openapi.json.
template <class Record, class F>
std::string json_type(const F& f) {
  using T = std::remove_cvref_t<decltype(f.get(std::declval<const Record&>()))>;
  if constexpr (std::is_floating_point_v<T>) {
    return "number";
  } else if constexpr (std::is_same_v<T, std::string>) {
    return "string";
  } else {
    return "integer";
  }
}

struct Expect {
  bool nullable_checked = true;  ///< numbers (null when not finite) and every joined field
  bool joined = false;           ///< the fields of the fix current at a sample's time
  bool doc = false;              ///< the description is the field table's doc
};

/// Every exported field of `table` is in `props` (an object schema's properties; for a schema of
/// columns, each array's items), with the type of its C++ member.
template <class Record, class Table>
void expect_described(const ordered_json& props, const Table& table, Expect e) {
  for_each_field<kExported>(table, [&](const auto& f) {
    SCOPED_TRACE(f.name);
    ASSERT_TRUE(props.contains(f.name)) << "openapi.json lacks the field";
    ordered_json p = props.at(f.name);
    if (p.value("type", "") == "array") p = p.at("items");
    const std::string type = json_type<Record>(f);
    EXPECT_EQ(p.value("type", ""), type);
    if (e.nullable_checked) {
      EXPECT_EQ(p.value("nullable", false), e.joined || type == "number");
    }
    if (e.doc) {
      EXPECT_EQ(p.value("description", ""), std::string(f.doc));
    }
  });
}

std::vector<std::string> keys_of(const ordered_json& object) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : object.items()) keys.push_back(key);
  return keys;
}

const ordered_json& schemas() {
  static const ordered_json spec = ordered_json::parse(kOpenApiJson);
  return spec.at("components").at("schemas");
}

// The sample exports' rows (CSV columns, JSON keys) are the field tables' exported fields after
// the sample's time; openapi.json's SampleRow must list exactly those, in that order, each with
// its type and the table's description.
TEST(SampleFieldsOpenApi, SampleRowListsExactlyTheExportedFieldsInOrder) {
  const ordered_json& props = schemas().at("SampleRow").at("properties");
  std::vector<std::string> want = {"time_utc", "t_s"};
  for_each_field<kExported>(kAttitudeFields, [&](const auto& f) { want.emplace_back(f.name); });
  for_each_field<kExported>(kFixFields, [&](const auto& f) { want.emplace_back(f.name); });
  EXPECT_EQ(keys_of(props), want);
  expect_described<AttitudeRow>(props, kAttitudeFields, {.doc = true});
  expect_described<FixSample>(props, kFixFields, {.joined = true, .doc = true});
}

// GET /boats carries every exported field of the sample and of the boat's fix; GET .../track a
// column of every exported field of the fix.
TEST(SampleFieldsOpenApi, BoatAndTrackCarryTheExportedFields) {
  const ordered_json& boat = schemas().at("Boat").at("properties");
  expect_described<AttitudeSample>(boat, kAttitudeFields, {});
  expect_described<FixSample>(boat, kFixFields, {.joined = true});
  const ordered_json& track = schemas().at("Track").at("properties");
  EXPECT_TRUE(track.contains("t_s"));
  expect_described<FixSample>(track, kFixFields, {.nullable_checked = false});
}

// The live frame and GET /boats are written straight to text (json_views.cpp boat_json): a boat
// with everything set carries exactly the properties the Boat schema describes, nested objects
// included, and its numbers read back to the same doubles.
TEST(SampleFieldsOpenApi, BoatJsonCarriesExactlyTheBoatSchema) {
  BoatView v;
  v.last.boat_id = "b-1";
  v.last.t_utc_ns = 1780000000123456789ULL;
  v.last.seq = 42;
  v.last.heel_deg = 17.3125;
  v.last.pitch_deg = -0.1;
  v.last.heading_deg = std::nan("");
  v.last.quality = 1.0 / 3.0;
  v.status = NodeStatusInfo{"boat", "0.9 \"rc\"\n", 12.5, 0, "ok", 7, "ilca"};
  v.fix = FixSample{};
  v.fix->fix = "3d";
  v.fix->lat_deg = 54.3412345678;
  v.fix->gnss_utc_ns = v.last.t_utc_ns + 40000000;
  v.fix->t_utc_ns = v.last.t_utc_ns;
  v.fix_fresh = true;
  const auto j = nlohmann::json::parse(boat_json(v));
  const ordered_json& boat = schemas().at("Boat").at("properties");
  std::vector<std::string> want = keys_of(boat);
  std::vector<std::string> got;
  for (const auto& [k, _] : j.items()) got.push_back(k);
  std::sort(want.begin(), want.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
  for (const char* nested : {"gnss", "leds"}) {
    std::vector<std::string> w = keys_of(boat.at(nested).at("properties"));
    std::vector<std::string> g;
    for (const auto& [k, _] : j.at(nested).items()) g.push_back(k);
    std::sort(w.begin(), w.end());
    std::sort(g.begin(), g.end());
    EXPECT_EQ(g, w) << nested;
  }
  EXPECT_EQ(j.at("t_utc_ns").get<std::uint64_t>(), v.last.t_utc_ns);
  EXPECT_EQ(j.at("heel_deg").get<double>(), v.last.heel_deg);
  EXPECT_EQ(j.at("quality").get<double>(), v.last.quality);
  EXPECT_TRUE(j.at("heading_deg").is_null());
  EXPECT_EQ(j.at("lat_deg").get<double>(), v.fix->lat_deg);
  EXPECT_EQ(j.at("gnss").at("clock_offset_ms").get<double>(), 40.0);
  EXPECT_EQ(j.at("status").at("software_version"), "0.9 \"rc\"\n");
  EXPECT_EQ(j.at("group"), "ilca");
}

}  // namespace
}  // namespace telltale::shore
