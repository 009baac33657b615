#pragma once
/// \file
/// One field table per stored record (the attitude sample, the GNSS fix, the wind): each field's
/// column name, SQL type, uses and meaning, and where it sits in the shore's structs. Everything
/// that lists the fields one by one is made from these tables: the CREATE TABLE, the migration that
/// adds a column missing from an older database, the INSERT, the row readers, the CSV header and
/// rows of the exports, the JSON keys of the exported rows and of GET /boats. openapi.json is
/// held to them by a test (tests/unit/sample_fields_test.cpp).
///
/// Adding a field to a record on the shore, one edit per layer: its member (fleet.hpp: AttitudeRow,
/// which AttitudeSample extends, or FixSample), one row here, its lines in wire.cpp (to_wire and
/// from_wire), its property in openapi.json (SampleRow, and Boat or Track). A field added after
/// a database was made must be nullable or have a DEFAULT (SQLite's ALTER TABLE ADD COLUMN rule):
/// the store adds it to an older database as it opens it.
///
/// Every table's key, written apart: boat_id TEXT and t_utc_ns INTEGER, the primary key.

#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <type_traits>

#include "fleet.hpp"
#include "store.hpp"

namespace telltale::shore {

/// What a field is used for, a bit set.
enum FieldUse : unsigned {
  kStored = 1,    ///< a column of the table, written by the INSERT
  kRead = 2,      ///< read back into the row struct (AttitudeRow, FixSample)
  kExported = 4,  ///< a column of the sample exports (CSV, JSON rows) and a key of GET /boats
};
inline constexpr unsigned kEveryUse = kStored | kRead | kExported;

/// How the CSV writes a number: "%.6g", or "%.7f" for coordinates (a centimetre).
enum class CsvFormat : std::uint8_t { kNumber, kCoordinate };

/// One field. `get(record)` is the member (works on every struct the table is used with).
template <unsigned Uses, class Get>
struct Field {
  static constexpr unsigned uses = Uses;
  const char* name;  ///< column name, CSV column and JSON key; the unit is in the name
  const char* sql;   ///< type and constraints in CREATE TABLE
  CsvFormat csv;
  const char* doc;  ///< meaning (openapi.json's description of it says the same)
  Get get;
};

template <unsigned Uses, class Get>
constexpr Field<Uses, Get> field(const char* name, const char* sql, CsvFormat csv, const char* doc,
                                 Get get) {
  return {name, sql, csv, doc, get};
}

/// The member `m` of whatever record is given, const or not.
#define TELLTALE_MEMBER(m) \
  [](auto& r) -> auto& { return r.m; }

/// The attitude sample, table `attitude`: AttitudeSample (stored), AttitudeRow (read back).
inline constexpr auto kAttitudeFields = std::make_tuple(
    field<kEveryUse>("seq", "INTEGER NOT NULL", CsvFormat::kNumber,
                     "per-boat sample counter, +1 per sample of a run", TELLTALE_MEMBER(seq)),
    field<kEveryUse>("heel_deg", "REAL NOT NULL", CsvFormat::kNumber, "+ = starboard side down",
                     TELLTALE_MEMBER(heel_deg)),
    field<kEveryUse>("pitch_deg", "REAL NOT NULL", CsvFormat::kNumber, "+ = bow up",
                     TELLTALE_MEMBER(pitch_deg)),
    field<kEveryUse>("heading_deg", "REAL", CsvFormat::kNumber,
                     "0..360 clockwise from north; null when the boat has no heading source",
                     TELLTALE_MEMBER(heading_deg)),
    field<kEveryUse>("heel_rate_deg_s", "REAL", CsvFormat::kNumber, "d(heel)/dt",
                     TELLTALE_MEMBER(heel_rate_deg_s)),
    field<kEveryUse>("pitch_rate_deg_s", "REAL", CsvFormat::kNumber, "d(pitch)/dt",
                     TELLTALE_MEMBER(pitch_rate_deg_s)),
    field<kEveryUse>("yaw_rate_deg_s", "REAL", CsvFormat::kNumber,
                     "body z rate, + = turning to port", TELLTALE_MEMBER(yaw_rate_deg_s)),
    field<kEveryUse>("accel_weight", "REAL", CsvFormat::kNumber,
                     "weight the fusion gave the accelerometer, 0..1",
                     TELLTALE_MEMBER(accel_weight)),
    field<kEveryUse>("quality", "REAL", CsvFormat::kNumber,
                     "0 (no confidence) .. 1 (fully consistent)", TELLTALE_MEMBER(quality)),
    field<kStored>("boot_id", "INTEGER NOT NULL DEFAULT 0", CsvFormat::kNumber,
                   "the boat node's run (two's complement of the random 64-bit id)",
                   TELLTALE_MEMBER(boot_id)));

/// The GNSS fix, table `fixes`: FixSample (stored and read back). The exported fields are those
/// of the fix current at each attitude sample's time, joined into the sample exports.
inline constexpr auto kFixFields = std::make_tuple(
    field<kStored | kRead>("seq", "INTEGER NOT NULL", CsvFormat::kNumber, "per-boat fix counter",
                           TELLTALE_MEMBER(seq)),
    field<kStored | kRead>("gnss_utc_ns", "INTEGER NOT NULL", CsvFormat::kNumber,
                           "the receiver's time of the fix; 0 when it gave none",
                           TELLTALE_MEMBER(gnss_utc_ns)),
    field<kEveryUse>("lat_deg", "REAL", CsvFormat::kCoordinate,
                     "WGS-84 latitude of the fix current at the sample's time; null without one",
                     TELLTALE_MEMBER(lat_deg)),
    field<kEveryUse>("lon_deg", "REAL", CsvFormat::kCoordinate, "WGS-84 longitude, + east",
                     TELLTALE_MEMBER(lon_deg)),
    field<kEveryUse>("sog_m_s", "REAL", CsvFormat::kNumber, "speed over ground",
                     TELLTALE_MEMBER(sog_m_s)),
    field<kEveryUse>("cog_deg", "REAL", CsvFormat::kNumber,
                     "course over ground, 0..360 from true north; null below 0.3 m/s",
                     TELLTALE_MEMBER(cog_deg)),
    field<kStored | kRead>("fix", "TEXT NOT NULL", CsvFormat::kNumber,
                           "none, 2d, 3d or dgnss (wire.hpp kFixKinds)", TELLTALE_MEMBER(fix)),
    field<kStored | kRead>("satellites", "INTEGER NOT NULL", CsvFormat::kNumber,
                           "satellites used; 0 when unknown", TELLTALE_MEMBER(satellites)),
    field<kStored | kRead>("hdop", "REAL", CsvFormat::kNumber,
                           "horizontal dilution of precision; null when unknown",
                           TELLTALE_MEMBER(hdop)),
    field<kStored | kRead>("boot_id", "INTEGER NOT NULL", CsvFormat::kNumber,
                           "the boat node's run, as in the attitude", TELLTALE_MEMBER(boot_id)));

/// The wind, table `wind`: WindSample (a wind instrument's readings, from imported logs).
inline constexpr auto kWindFields = std::make_tuple(
    field<kStored | kRead>("from_deg", "REAL NOT NULL", CsvFormat::kNumber,
                           "true wind direction it blows from, 0..360 clockwise from true north",
                           TELLTALE_MEMBER(from_deg)),
    field<kStored | kRead>("speed_m_s", "REAL", CsvFormat::kNumber,
                           "true wind speed; null when the instrument gave none",
                           TELLTALE_MEMBER(speed_m_s)),
    field<kStored | kRead>("source", "TEXT NOT NULL DEFAULT ''", CsvFormat::kNumber,
                           "what it was made from: mwd, mwv_true, mwv_apparent, vkx_apparent",
                           TELLTALE_MEMBER(source)));

#undef TELLTALE_MEMBER

/// Calls `f(field)` for every field of `table` with all of `uses`, in the table's order.
template <unsigned Uses, class Table, class F>
constexpr void for_each_field(const Table& table, F&& f) {
  std::apply(
      [&](const auto&... fields) {
        (
            [&](const auto& one) {
              if constexpr ((std::remove_cvref_t<decltype(one)>::uses & Uses) == Uses) f(one);
            }(fields),
            ...);
      },
      table);
}

/// "a, b, c": the names of the fields with `Uses`, in order, between `separator`s.
template <unsigned Uses, class Table>
std::string field_names(const Table& table, const char* separator = ", ") {
  std::string out;
  for_each_field<Uses>(table, [&](const auto& f) {
    if (!out.empty()) out += separator;
    out += f.name;
  });
  return out;
}

/// CREATE TABLE of a sample table: the key, then every stored field.
template <class Table>
std::string create_table_sql(const char* table_name, const Table& table) {
  std::string sql = std::string("CREATE TABLE IF NOT EXISTS ") + table_name +
                    " (\n  boat_id TEXT NOT NULL,\n  t_utc_ns INTEGER NOT NULL,\n";
  for_each_field<kStored>(
      table, [&](const auto& f) { sql += std::string("  ") + f.name + " " + f.sql + ",\n"; });
  return sql + "  PRIMARY KEY (boat_id, t_utc_ns)\n) WITHOUT ROWID;\n";
}

/// INSERT OR IGNORE of one record: ?1 boat_id, ?2 t_utc_ns, then the stored fields in order
/// (bind_fields from 3).
template <class Table>
std::string insert_sql(const char* table_name, const Table& table) {
  std::string sql = std::string("INSERT OR IGNORE INTO ") + table_name + " (boat_id, t_utc_ns";
  std::string values = "?,?";
  for_each_field<kStored>(table, [&](const auto& f) {
    sql += std::string(", ") + f.name;
    values += ",?";
  });
  return sql + ") VALUES (" + values + ")";
}

/// "t_utc_ns, <read fields>": the columns read_fields expects from column 1 on.
template <class Table>
std::string select_columns(const Table& table) {
  return "t_utc_ns, " + field_names<kRead>(table);
}

/// Binds one value: integers as int64 (two's complement above INT64_MAX), a number that is not
/// finite as NULL, text as text.
template <class T>
void bind_value(sqlite3_stmt* st, int i, const T& v) {
  if constexpr (std::is_same_v<T, std::string>) {
    sqlite3_bind_text(st, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (std::isfinite(v)) {
      sqlite3_bind_double(st, i, static_cast<double>(v));
    } else {
      sqlite3_bind_null(st, i);
    }
  } else {
    static_assert(std::is_integral_v<T>);
    sqlite3_bind_int64(st, i, static_cast<sqlite3_int64>(v));
  }
}

/// Reads one value back: NULL as NaN for numbers.
template <class T>
void read_value(sqlite3_stmt* st, int c, T& v) {
  if constexpr (std::is_same_v<T, std::string>) {
    const auto* p = sqlite3_column_text(st, c);
    v = p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  } else if constexpr (std::is_floating_point_v<T>) {
    v = sqlite3_column_type(st, c) == SQLITE_NULL ? std::nan("")
                                                  : static_cast<T>(sqlite3_column_double(st, c));
  } else {
    static_assert(std::is_integral_v<T>);
    v = static_cast<T>(sqlite3_column_int64(st, c));
  }
}

/// Binds the stored fields of `record` from parameter `first` on; the next parameter's index.
template <class Table, class Record>
int bind_fields(sqlite3_stmt* st, int first, const Table& table, const Record& record) {
  for_each_field<kStored>(table, [&](const auto& f) { bind_value(st, first++, f.get(record)); });
  return first;
}

/// Reads the read-back fields into `record` from column `first` on.
template <class Table, class Record>
void read_fields(sqlite3_stmt* st, int first, const Table& table, Record& record) {
  for_each_field<kRead>(table, [&](const auto& f) { read_value(st, first++, f.get(record)); });
}

}  // namespace telltale::shore
