#pragma once
/// \file
/// The shore's one wrapper of an SQLite prepared statement (store, imports): finalised with its
/// scope, every failure a StoreError, NaN bound and read back as NULL.

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "store_error.hpp"

namespace telltale::shore {

/// A prepared statement that finalises itself and throws StoreError on failure.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &st_, nullptr) != SQLITE_OK)
      throw StoreError(sqlite3_errmsg(db));
  }
  ~Stmt() { sqlite3_finalize(st_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;

  Stmt& bind(int i, std::int64_t v) {
    sqlite3_bind_int64(st_, i, v);
    return *this;
  }
  Stmt& bind_u(int i, std::uint64_t v) {
    // Nanoseconds since 1970 fit int64 until 2262.
    sqlite3_bind_int64(st_, i,
                       static_cast<sqlite3_int64>(
                           std::min<std::uint64_t>(v, static_cast<std::uint64_t>(INT64_MAX))));
    return *this;
  }
  Stmt& bind(int i, double v) {
    if (std::isfinite(v)) {
      sqlite3_bind_double(st_, i, v);
    } else {
      sqlite3_bind_null(st_, i);
    }
    return *this;
  }
  Stmt& bind(int i, const std::string& v) {
    sqlite3_bind_text(st_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  /// True on a row, false when done.
  bool step() {
    const int rc = sqlite3_step(st_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw StoreError(sqlite3_errmsg(db_));
  }
  void reset() {
    sqlite3_reset(st_);
    sqlite3_clear_bindings(st_);
  }
  /// Steps a write and resets for the next one (bindings kept); the rows it changed.
  int run() {
    step();
    const int n = sqlite3_changes(db_);
    sqlite3_reset(st_);
    return n;
  }
  std::int64_t i64(int c) const { return sqlite3_column_int64(st_, c); }
  std::uint64_t u64(int c) const {
    return static_cast<std::uint64_t>(sqlite3_column_int64(st_, c));
  }
  double dbl(int c) const {
    return sqlite3_column_type(st_, c) == SQLITE_NULL ? std::numeric_limits<double>::quiet_NaN()
                                                      : sqlite3_column_double(st_, c);
  }
  std::string text(int c) const {
    const auto* p = sqlite3_column_text(st_, c);
    return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  }
  sqlite3_stmt* get() const { return st_; }

 private:
  sqlite3* db_;
  sqlite3_stmt* st_ = nullptr;
};

/// Runs SQL text (no results); throws StoreError.
inline void exec(sqlite3* db, const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw StoreError(msg);
  }
}

}  // namespace telltale::shore
