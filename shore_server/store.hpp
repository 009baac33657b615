#pragma once
/// \file
/// The shore's recording: every attitude sample into SQLite (WAL). Samples are queued by the DDS
/// listener and committed by one writer thread in batches. Durability window: a sample is on disk
/// at most `commit_interval` after it arrived (default 250 ms); a crash loses at most that window,
/// which the boats' backfill refills. A sample already stored (same boat, same UTC time) is kept
/// once (INSERT OR IGNORE), so re-sent samples merge without duplicates.

#include <sqlite3.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fleet.hpp"

namespace telltale::shore {

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SampleStore {
 public:
  /// Opens or creates the database and its schema. Throws StoreError.
  SampleStore(const std::string& path, std::chrono::milliseconds commit_interval);
  /// Commits what is queued, then closes.
  ~SampleStore();
  SampleStore(const SampleStore&) = delete;
  SampleStore& operator=(const SampleStore&) = delete;

  /// Queues one sample (never blocks on disk).
  void enqueue(const AttitudeSample& sample);
  /// Samples stored for a boat (committed ones), for tests and the health check.
  [[nodiscard]] std::int64_t count(const std::string& boat_id);
  [[nodiscard]] std::uint64_t committed() const;
  /// Last error of the writer thread, empty if none.
  [[nodiscard]] std::string last_error() const;

 private:
  void writer_loop();
  void commit(std::vector<AttitudeSample>& batch);

  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_ = nullptr;
  std::chrono::milliseconds commit_interval_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<AttitudeSample> queue_;
  bool stopping_ = false;
  std::uint64_t committed_ = 0;
  std::string last_error_;
  std::mutex db_mutex_;  ///< serialises use of db_ between the writer and readers
  std::thread writer_;
};

}  // namespace telltale::shore
