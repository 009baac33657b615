#include "store.hpp"

namespace telltale::shore {
namespace {

constexpr const char* kSchema = R"sql(
PRAGMA journal_mode = WAL;
PRAGMA synchronous = NORMAL;
CREATE TABLE IF NOT EXISTS attitude (
  boat_id TEXT NOT NULL,
  t_utc_ns INTEGER NOT NULL,
  seq INTEGER NOT NULL,
  heel_deg REAL NOT NULL,
  pitch_deg REAL NOT NULL,
  heading_deg REAL,
  heel_rate_deg_s REAL,
  pitch_rate_deg_s REAL,
  yaw_rate_deg_s REAL,
  accel_weight REAL,
  quality REAL,
  PRIMARY KEY (boat_id, t_utc_ns)
) WITHOUT ROWID;
)sql";

void exec(sqlite3* db, const char* sql) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw StoreError(msg);
  }
}

}  // namespace

SampleStore::SampleStore(const std::string& path, std::chrono::milliseconds commit_interval)
    : commit_interval_(commit_interval) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE |
                                              SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw StoreError("cannot open database " + path + ": " + msg);
  }
  try {
    sqlite3_busy_timeout(db_, 5000);
    exec(db_, kSchema);
    if (sqlite3_prepare_v2(db_,
                           "INSERT OR IGNORE INTO attitude (boat_id, t_utc_ns, seq, heel_deg, "
                           "pitch_deg, heading_deg, heel_rate_deg_s, pitch_rate_deg_s, "
                           "yaw_rate_deg_s, accel_weight, quality) "
                           "VALUES (?,?,?,?,?,?,?,?,?,?,?)",
                           -1, &insert_, nullptr) != SQLITE_OK)
      throw StoreError(sqlite3_errmsg(db_));
  } catch (const StoreError& e) {
    sqlite3_finalize(insert_);
    sqlite3_close(db_);
    throw StoreError("database " + path + ": " + e.what());
  }
  writer_ = std::thread([this] { writer_loop(); });
}

SampleStore::~SampleStore() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  writer_.join();
  sqlite3_finalize(insert_);
  sqlite3_close(db_);
}

void SampleStore::enqueue(const AttitudeSample& sample) {
  std::lock_guard lock(mutex_);
  queue_.push_back(sample);
}

void SampleStore::writer_loop() {
  std::vector<AttitudeSample> batch;
  for (;;) {
    bool stop = false;
    {
      std::unique_lock lock(mutex_);
      cv_.wait_for(lock, commit_interval_, [this] { return stopping_; });
      stop = stopping_;
      batch.swap(queue_);
    }
    if (!batch.empty()) commit(batch);
    batch.clear();
    if (stop) return;
  }
}

void SampleStore::commit(std::vector<AttitudeSample>& batch) {
  std::lock_guard db_lock(db_mutex_);
  try {
    exec(db_, "BEGIN");
    for (const auto& s : batch) {
      sqlite3_reset(insert_);
      sqlite3_bind_text(insert_, 1, s.boat_id.c_str(), static_cast<int>(s.boat_id.size()),
                        SQLITE_TRANSIENT);
      sqlite3_bind_int64(insert_, 2, static_cast<sqlite3_int64>(s.t_utc_ns));
      sqlite3_bind_int64(insert_, 3, static_cast<sqlite3_int64>(s.seq));
      sqlite3_bind_double(insert_, 4, s.heel_deg);
      sqlite3_bind_double(insert_, 5, s.pitch_deg);
      // SQLite stores NaN as NULL: no heading source.
      sqlite3_bind_double(insert_, 6, s.heading_deg);
      sqlite3_bind_double(insert_, 7, s.heel_rate_deg_s);
      sqlite3_bind_double(insert_, 8, s.pitch_rate_deg_s);
      sqlite3_bind_double(insert_, 9, s.yaw_rate_deg_s);
      sqlite3_bind_double(insert_, 10, static_cast<double>(s.accel_weight));
      sqlite3_bind_double(insert_, 11, static_cast<double>(s.quality));
      if (sqlite3_step(insert_) != SQLITE_DONE) throw StoreError(sqlite3_errmsg(db_));
    }
    exec(db_, "COMMIT");
    std::lock_guard lock(mutex_);
    committed_ += batch.size();
    last_error_.clear();
  } catch (const StoreError& e) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    // Keep the batch for the next attempt (disk full, locked): nothing already received is lost
    // while the process lives.
    std::lock_guard lock(mutex_);
    last_error_ = e.what();
    queue_.insert(queue_.begin(), batch.begin(), batch.end());
  }
}

std::int64_t SampleStore::count(const std::string& boat_id) {
  std::lock_guard db_lock(db_mutex_);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db_, "SELECT COUNT(*) FROM attitude WHERE boat_id = ?", -1, &st, nullptr);
  sqlite3_bind_text(st, 1, boat_id.c_str(), static_cast<int>(boat_id.size()), SQLITE_TRANSIENT);
  std::int64_t n = -1;
  if (sqlite3_step(st) == SQLITE_ROW) n = sqlite3_column_int64(st, 0);
  sqlite3_finalize(st);
  return n;
}

std::uint64_t SampleStore::committed() const {
  std::lock_guard lock(mutex_);
  return committed_;
}

std::string SampleStore::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

}  // namespace telltale::shore
