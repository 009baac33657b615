#pragma once
/// \file
/// What the shore's database holds of a boat, read from the file with a read-only connection
/// (the shore keeps running): for tests that compare it with what the boat published.

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace telltale::testing {

/// The distinct seqs in 1..max_seq the database at `db_path` holds for the boat (of run
/// `boot_id` only, if given), ascending; nothing if the file cannot be read.
inline std::optional<std::vector<long>> stored_seq_list(
    const std::string& db_path, const std::string& boat, long max_seq,
    std::optional<std::uint64_t> boot_id = std::nullopt) {
  sqlite3* db = nullptr;
  std::optional<std::vector<long>> out;
  if (sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db,
                           "SELECT DISTINCT seq FROM attitude WHERE boat_id = ?1 AND seq BETWEEN "
                           "1 AND ?2 AND (?3 IS NULL OR boot_id = ?3) ORDER BY seq",
                           -1, &st, nullptr) == SQLITE_OK) {
      sqlite3_bind_text(st, 1, boat.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_int64(st, 2, max_seq);
      // Boot ids are stored as their two's-complement int64.
      if (boot_id) sqlite3_bind_int64(st, 3, static_cast<sqlite3_int64>(*boot_id));
      out.emplace();
      while (sqlite3_step(st) == SQLITE_ROW)
        out->push_back(static_cast<long>(sqlite3_column_int64(st, 0)));
    }
    sqlite3_finalize(st);
  }
  sqlite3_close(db);
  return out;
}

/// How many distinct seqs in 1..max_seq the database holds for the boat (of run `boot_id` only,
/// if given); -1 if the file cannot be read.
inline long stored_seqs(const std::string& db_path, const std::string& boat, long max_seq,
                        std::optional<std::uint64_t> boot_id = std::nullopt) {
  const auto seqs = stored_seq_list(db_path, boat, max_seq, boot_id);
  return seqs ? static_cast<long>(seqs->size()) : -1;
}

/// The seqs in 1..max_seq the database does not hold for the boat, as ranges ("812-815 990"), for
/// failure messages: which samples were lost tells a kill's gap from a drain cut short.
inline std::string missing_seqs(const std::string& db_path, const std::string& boat, long max_seq) {
  const auto seqs = stored_seq_list(db_path, boat, max_seq);
  if (!seqs) return "(database unreadable)";
  std::string out;
  const auto gap = [&](long first, long last) {
    if (first > last) return;
    if (!out.empty()) out += ' ';
    out +=
        first == last ? std::to_string(first) : std::to_string(first) + "-" + std::to_string(last);
  };
  long expected = 1;
  for (const long seq : *seqs) {
    gap(expected, seq - 1);
    expected = seq + 1;
  }
  gap(expected, max_seq);
  return out;
}

}  // namespace telltale::testing
