#include "store.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "chart_tiers.hpp"
#include "sample_fields.hpp"
#include "sqlite_stmt.hpp"

namespace telltale::shore {
namespace {

/// Every table but the two sample tables, whose CREATE TABLE comes from their field tables
/// (sample_fields.hpp).
constexpr const char* kSchema = R"sql(
PRAGMA journal_mode = WAL;
PRAGMA synchronous = NORMAL;
CREATE TABLE IF NOT EXISTS wearable (
  athlete_id TEXT NOT NULL,
  t_utc_ns INTEGER NOT NULL,
  seq INTEGER NOT NULL,
  steps INTEGER NOT NULL,
  cadence_spm REAL,
  gait TEXT NOT NULL,
  pose TEXT NOT NULL,
  x_m REAL,
  y_m REAL,
  heading_deg REAL,
  distance_m REAL,
  PRIMARY KEY (athlete_id, t_utc_ns)
) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS sessions (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  boat_id TEXT NOT NULL,
  start_ns INTEGER NOT NULL,
  end_ns INTEGER NOT NULL,
  samples INTEGER NOT NULL,
  received_ns INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS sessions_by_boat ON sessions (boat_id, end_ns);
CREATE TABLE IF NOT EXISTS alarm_rules (
  id TEXT PRIMARY KEY,
  position INTEGER NOT NULL,
  scope TEXT NOT NULL,
  quantity TEXT NOT NULL,
  min_deg REAL NOT NULL,
  max_deg REAL NOT NULL,
  hold_s REAL NOT NULL,
  hysteresis_deg REAL NOT NULL,
  level TEXT NOT NULL,
  enabled INTEGER NOT NULL
);
CREATE TABLE IF NOT EXISTS alarm_events (
  id INTEGER PRIMARY KEY,
  boat_id TEXT NOT NULL,
  rule_id TEXT NOT NULL,
  level TEXT NOT NULL,
  phase TEXT NOT NULL,
  raised_ns INTEGER NOT NULL,
  acknowledged_ns INTEGER NOT NULL,
  silenced_ns INTEGER NOT NULL,
  cleared_ns INTEGER NOT NULL,
  value_deg REAL NOT NULL,
  message TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS alarm_events_by_time ON alarm_events (raised_ns);
CREATE TABLE IF NOT EXISTS boat_aliases (
  boat_id TEXT NOT NULL,
  boot_id INTEGER NOT NULL,
  alias TEXT NOT NULL,
  PRIMARY KEY (boat_id, boot_id)
) WITHOUT ROWID;
)sql";

sqlite3* open_db(const std::string& path, int flags) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK) {
    std::string msg = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    throw StoreError("cannot open database " + path + ": " + msg);
  }
  sqlite3_busy_timeout(db, 5000);
  return db;
}

/// The schema this build writes. Version 1: attitude gained boot_id (the boats' run id, for
/// backfill receipts). Version 2: sessions gained received_ns (the shore's arrival time, for
/// retention; 0 in older rows: their end_ns stands in). Databases from earlier builds are
/// migrated in place; a database from a newer build is refused rather than misread. Version 3:
/// chart tiers (chart_tiers.hpp), built for older databases. Version 4: the tiers are kept by the
/// inserting code, no longer by a trigger, which is dropped.
constexpr int kSchemaVersion = 4;

/// ALTER TABLE ADD COLUMN for every stored field of `table` that `table_name` lacks.
template <class Table>
void add_missing_columns(sqlite3* db, const char* table_name, const Table& table) {
  for_each_field<kStored>(table, [&](const auto& f) {
    Stmt has(db, "SELECT COUNT(*) FROM pragma_table_info(?1) WHERE name = ?2");
    has.bind(1, std::string(table_name)).bind(2, std::string(f.name));
    if (has.step() && has.i64(0) == 0)
      exec(db, (std::string("ALTER TABLE ") + table_name + " ADD COLUMN " + f.name + " " + f.sql)
                   .c_str());
  });
}

void migrate(sqlite3* db) {
  Stmt version_q(db, "PRAGMA user_version");
  const int version = version_q.step() ? static_cast<int>(version_q.i64(0)) : 0;
  if (version > kSchemaVersion)
    throw StoreError("written by a newer Telltale (schema " + std::to_string(version) +
                     ", this build knows " + std::to_string(kSchemaVersion) + ")");
  // A field of a sample table that an older database lacks (attitude.boot_id before version 1)
  // is added as the field table defines it.
  add_missing_columns(db, "attitude", kAttitudeFields);
  add_missing_columns(db, "fixes", kFixFields);
  Stmt has_received(
      db, "SELECT COUNT(*) FROM pragma_table_info('sessions') WHERE name = 'received_ns'");
  if (has_received.step() && has_received.i64(0) == 0)
    exec(db, "ALTER TABLE sessions ADD COLUMN received_ns INTEGER NOT NULL DEFAULT 0");
  if (version < 3) rebuild_tiers(db, "", 0, std::numeric_limits<std::int64_t>::max());
  if (version < 4) exec(db, "DROP TRIGGER IF EXISTS attitude_tiers");
  exec(db, ("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
}

SessionInfo session_from(const Stmt& s) {
  return {s.i64(0), s.text(1), s.u64(2), s.u64(3), s.i64(4)};
}

/// A row of select_columns(kAttitudeFields).
AttitudeRow row_from(const Stmt& s) {
  AttitudeRow r;
  r.t_utc_ns = s.u64(0);
  read_fields(s.get(), 1, kAttitudeFields, r);
  return r;
}

AlarmEvent event_from(const Stmt& s) {
  AlarmEvent e;
  e.id = s.u64(0);
  e.boat_id = s.text(1);
  e.rule_id = s.text(2);
  e.level = parse_level(s.text(3)).value_or(AlarmLevel::kWarn);
  e.phase = parse_phase(s.text(4)).value_or(AlarmPhase::kRaised);
  e.raised_ns = s.u64(5);
  e.acknowledged_ns = s.u64(6);
  e.silenced_ns = s.u64(7);
  e.cleared_ns = s.u64(8);
  e.value_deg = s.dbl(9);
  e.message = s.text(10);
  return e;
}

constexpr const char* kSessionColumns = "id, boat_id, start_ns, end_ns, samples";
constexpr const char* kEventColumns =
    "id, boat_id, rule_id, level, phase, raised_ns, acknowledged_ns, silenced_ns, cleared_ns, "
    "value_deg, message";

}  // namespace

/// One read-only connection, taken from the idle ones for the lease's scope.
class Store::ReadLease {
 public:
  explicit ReadLease(Store& store) : store_(store) {
    std::unique_lock lock(store_.readers_mutex_);
    store_.reader_idle_.wait(lock, [&] { return !store_.idle_readers_.empty(); });
    db_ = store_.idle_readers_.back();
    store_.idle_readers_.pop_back();
  }
  ~ReadLease() {
    {
      std::lock_guard lock(store_.readers_mutex_);
      store_.idle_readers_.push_back(db_);
    }
    store_.reader_idle_.notify_one();
  }
  ReadLease(const ReadLease&) = delete;
  ReadLease& operator=(const ReadLease&) = delete;
  [[nodiscard]] sqlite3* db() const { return db_; }

 private:
  Store& store_;
  sqlite3* db_ = nullptr;
};

Store::Store(StoreConfig config) : config_(std::move(config)) {
  db_ = open_db(config_.path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  try {
    exec(db_, kSchema);
    // The writer's page cache: SQLite's default 2 MB holds the index pages of a few hundred
    // boats; beyond that every insert re-reads pages from the WAL (pread was the writer's second
    // cost at 1000 boats, and a 64 MB cache cut its CPU per commit by a quarter:
    // bench/store_bench.cpp). Readers keep the default: they read ranges, not scattered pages.
    exec(db_, "PRAGMA cache_size = -65536");
    exec(db_, create_table_sql("attitude", kAttitudeFields).c_str());
    exec(db_, create_table_sql("fixes", kFixFields).c_str());
    exec(db_, create_table_sql("wind", kWindFields).c_str());
    create_tier_table(db_);
    migrate(db_);
    load_aliases();
    for (std::size_t i = 0; i < kReaders; ++i)
      readers_.push_back(open_db(config_.path, SQLITE_OPEN_READONLY));
    idle_readers_ = readers_;
    if (sqlite3_prepare_v2(db_, insert_sql("attitude", kAttitudeFields).c_str(), -1, &insert_,
                           nullptr) != SQLITE_OK)
      throw StoreError(sqlite3_errmsg(db_));
  } catch (const StoreError& e) {
    for (auto* r : readers_) sqlite3_close(r);
    sqlite3_close(db_);
    throw StoreError("database " + config_.path + ": " + e.what());
  }
  next_retention_ = std::chrono::steady_clock::now();
  writer_ = std::thread([this] { writer_loop(); });
}

Store::~Store() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  writer_.join();  // its last round commits what is queued, backoff or not
  if (!queue_.empty()) {
    // Not on disk and never acknowledged: say loudly what, per boat run. The boats still hold
    // these samples in their session logs and deliver them at their next contact with a shore.
    std::map<std::pair<std::string, std::uint64_t>, std::pair<std::uint64_t, std::uint64_t>> runs;
    for (const auto& s : queue_) {
      const auto it = runs.try_emplace({s.boat_id, s.boot_id}, s.seq, s.seq).first;
      it->second.first = std::min(it->second.first, s.seq);
      it->second.second = std::max(it->second.second, s.seq);
    }
    std::string what;
    for (const auto& [key, range] : runs) {
      char line[160];
      std::snprintf(line, sizeof line, "%s%s run %016llx seq %llu-%llu", what.empty() ? "" : ", ",
                    key.first.c_str(), static_cast<unsigned long long>(key.second),
                    static_cast<unsigned long long>(range.first),
                    static_cast<unsigned long long>(range.second));
      what += line;
    }
    std::fprintf(stderr,
                 "shore_server: STORE: %zu samples could not be saved at stop (%s): %s. They were "
                 "never acknowledged, so the boats keep them in their session logs and resend "
                 "them to the next shore that runs.\n",
                 queue_.size(), last_error_.c_str(), what.c_str());
  }
  if (dropped_ > 0)
    std::fprintf(stderr,
                 "shore_server: STORE: %llu samples were refused while the backlog was full; "
                 "never acknowledged, the boats resend them from their logs.\n",
                 static_cast<unsigned long long>(dropped_));
  sqlite3_finalize(insert_);
  for (auto* r : readers_) sqlite3_close(r);
  sqlite3_close(db_);  // the last connection checkpoints and removes the WAL
}

void Store::enqueue(const AttitudeSample& sample) {
  std::lock_guard lock(mutex_);
  if (queue_.size() >= config_.max_backlog) {
    // Commits are failing and the backlog is full: memory stays bounded. The sample is never
    // acknowledged, so its boat resends it from the session log once the shore stores again.
    ++dropped_;
    return;
  }
  queue_.push_back(sample);
  ++enqueued_;
}

void Store::enqueue(const WearableSample& sample) {
  std::lock_guard lock(mutex_);
  push_bounded(wearable_queue_, sample, dropped_wearable_);
}

template <class T>
void Store::requeue(std::vector<T>& batch, std::vector<T>& queue, std::uint64_t& dropped,
                    std::size_t& in_hand) {
  std::lock_guard lock(mutex_);
  in_hand = 0;
  // The failed batch is older than what came meanwhile: it goes first.
  batch.insert(batch.end(), queue.begin(), queue.end());
  queue.swap(batch);
  if (queue.size() > config_.max_backlog) {
    const std::size_t over = queue.size() - config_.max_backlog;
    dropped += over;
    queue.erase(queue.begin(), queue.begin() + static_cast<std::ptrdiff_t>(over));
  }
}

bool Store::transaction(const char* what, const std::function<void()>& write,
                        const std::function<void()>& committed) {
  std::lock_guard db_lock(db_mutex_);
  try {
    exec(db_, "BEGIN");
    write();
    exec(db_, "COMMIT");
    if (committed) committed();
    return true;
  } catch (const StoreError& e) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    std::lock_guard lock(mutex_);
    last_error_ = std::string(what) + ": " + e.what();
    return false;
  }
}

bool Store::commit_wearable(const std::vector<WearableSample>& batch) {
  return transaction("wearable", [&] {
    Stmt ins(db_,
             "INSERT OR IGNORE INTO wearable (athlete_id, t_utc_ns, seq, steps, cadence_spm, "
             "gait, pose, x_m, y_m, heading_deg, distance_m) VALUES (?,?,?,?,?,?,?,?,?,?,?)");
    for (const auto& w : batch) {
      ins.reset();
      ins.bind(1, w.athlete_id).bind_u(2, w.t_utc_ns).bind_u(3, w.seq);
      ins.bind(4, static_cast<std::int64_t>(w.steps)).bind(5, w.cadence_spm).bind(6, w.gait);
      ins.bind(7, w.pose).bind(8, w.x_m).bind(9, w.y_m).bind(10, w.heading_deg);
      ins.bind(11, w.distance_m);
      ins.step();
    }
  });
}

void Store::enqueue(const WindSample& wind) {
  std::lock_guard lock(mutex_);
  if (push_bounded(wind_queue_, wind, dropped_wind_)) ++wind_enqueued_;
}

bool Store::commit_wind(const std::vector<WindSample>& batch) {
  return transaction("wind", [&] {
    Stmt ins(db_, insert_sql("wind", kWindFields).c_str());
    for (const auto& w : batch) {
      ins.reset();
      // A second node's run has its own id (recorded_id), as its fixes do.
      const auto alias = aliases_.find({w.boat_id, w.boot_id});
      ins.bind(1, alias == aliases_.end() ? w.boat_id : alias->second);
      ins.bind_u(2, w.t_utc_ns);
      bind_fields(ins.get(), 3, kWindFields, w);
      ins.step();
    }
  });
}

void Store::enqueue(const FixSample& fix) {
  std::lock_guard lock(mutex_);
  if (push_bounded(fix_queue_, fix, dropped_fixes_)) ++fixes_enqueued_;
}

bool Store::commit_fixes(const std::vector<FixSample>& batch) {
  return transaction(
      "fixes",
      [&] {
        Stmt ins(db_, insert_sql("fixes", kFixFields).c_str());
        for (const auto& f : batch) {
          ins.reset();
          // A second node's run has its own id (recorded_id): its fixes go with its samples.
          const auto alias = aliases_.find({f.boat_id, f.boot_id});
          ins.bind(1, alias == aliases_.end() ? f.boat_id : alias->second);
          ins.bind_u(2, f.t_utc_ns);
          bind_fields(ins.get(), 3, kFixFields, f);
          ins.step();
        }
      },
      [&] {
        // On disk now: these fixes may be acknowledged to their boats.
        for (const auto& f : batch) track_fix_receipt(f);
        std::lock_guard lock(mutex_);
        fixes_committed_ += batch.size();
      });
}

std::vector<FixSample> Store::fix_page(const std::string& boat_id, std::uint64_t after_ns,
                                       std::uint64_t to_ns, std::size_t limit) {
  const ReadLease reader(*this);
  static const std::string kSql = "SELECT " + select_columns(kFixFields) +
                                  " FROM fixes WHERE boat_id = ? AND t_utc_ns > ? AND "
                                  "t_utc_ns <= ? AND fix <> 'none' ORDER BY t_utc_ns LIMIT ?";
  Stmt q(reader.db(), kSql.c_str());
  q.bind(1, boat_id).bind_u(2, after_ns).bind_u(3, to_ns).bind(4, static_cast<std::int64_t>(limit));
  std::vector<FixSample> rows;
  while (q.step()) {
    FixSample f;
    f.boat_id = boat_id;
    f.t_utc_ns = q.u64(0);
    read_fields(q.get(), 1, kFixFields, f);
    rows.push_back(std::move(f));
  }
  return rows;
}

void Store::visit_fixes(const std::string& boat_id, std::uint64_t from_ns, std::uint64_t to_ns,
                        const std::function<bool(const FixSample&)>& visit, std::size_t page) {
  if (from_ns > to_ns) return;
  // Exclusive keyset: the first page starts just before from_ns.
  std::uint64_t after = from_ns == 0 ? 0 : from_ns - 1;
  // (t_utc_ns 0 is off the contract, the door refuses it: "> 0" misses nothing.)
  for (;;) {
    const auto rows = fix_page(boat_id, after, to_ns, page);
    for (const auto& f : rows)
      if (!visit(f)) return;
    if (rows.size() < page) return;
    after = rows.back().t_utc_ns;
  }
}

std::vector<WindSample> Store::wind(const std::string& boat_id, std::uint64_t from_ns,
                                    std::uint64_t to_ns, std::size_t limit) {
  std::vector<WindSample> all;
  if (from_ns > to_ns || limit == 0) return all;
  {
    const ReadLease reader(*this);
    static const std::string kSql = "SELECT " + select_columns(kWindFields) +
                                    " FROM wind WHERE boat_id = ? AND t_utc_ns BETWEEN ? AND ? "
                                    "ORDER BY t_utc_ns";
    Stmt q(reader.db(), kSql.c_str());
    q.bind(1, boat_id)
        .bind_u(2, from_ns)
        .bind_u(3, std::min<std::uint64_t>(to_ns, std::numeric_limits<std::int64_t>::max()));
    while (q.step()) {
      WindSample w;
      w.boat_id = boat_id;
      w.t_utc_ns = q.u64(0);
      read_fields(q.get(), 1, kWindFields, w);
      all.push_back(std::move(w));
    }
  }
  if (all.size() <= limit) return all;
  std::vector<WindSample> out;
  out.reserve(limit);
  const double step = static_cast<double>(all.size() - 1) /
                      static_cast<double>(std::max<std::size_t>(limit - 1, 1));
  for (std::size_t i = 0; i < limit; ++i)
    out.push_back(all[std::min(
        all.size() - 1, static_cast<std::size_t>(std::llround(step * static_cast<double>(i))))]);
  return out;
}

std::vector<FixSample> Store::track(const std::string& boat_id, std::uint64_t from_ns,
                                    std::uint64_t to_ns, std::size_t max_points) {
  std::vector<FixSample> all;
  visit_fixes(boat_id, from_ns, to_ns, [&](const FixSample& f) {
    all.push_back(f);
    return true;
  });
  if (max_points == 0 || all.size() <= max_points) return all;
  // Even in time, not in count: a receiver that paused does not get its points crowded.
  std::vector<FixSample> out;
  out.reserve(max_points);
  const double t0 = static_cast<double>(all.front().t_utc_ns);
  const double span = static_cast<double>(all.back().t_utc_ns) - t0;
  std::size_t i = 0;
  for (std::size_t k = 0; k < max_points && i < all.size(); ++k) {
    const double target = t0 + span * static_cast<double>(k) / static_cast<double>(max_points - 1);
    while (i + 1 < all.size() && static_cast<double>(all[i].t_utc_ns) < target) ++i;
    if (out.empty() || out.back().t_utc_ns != all[i].t_utc_ns) out.push_back(all[i]);
  }
  if (out.back().t_utc_ns != all.back().t_utc_ns) out.back() = all.back();
  return out;
}

FixStats Store::fix_stats(const std::string& boat_id, std::uint64_t from_ns, std::uint64_t to_ns) {
  // Distance sailed: the receiver's speed (Doppler, ~0.05 m/s noise) integrated over time, not
  // the sum of position steps: at 10 Hz a metre of position scatter between fixes would add
  // more than the boat sails. A gap longer than 5 s (receiver or link silent) adds nothing: the
  // boat's speed over it is unknown.
  FixStats st;
  std::uint64_t prev_t = 0;
  double prev_sog = std::numeric_limits<double>::quiet_NaN();
  double max_sog = std::numeric_limits<double>::quiet_NaN();
  visit_fixes(boat_id, from_ns, to_ns, [&](const FixSample& f) {
    ++st.fixes;
    if (std::isfinite(f.sog_m_s) && !(f.sog_m_s <= max_sog)) max_sog = f.sog_m_s;
    if (prev_t != 0 && std::isfinite(prev_sog) && std::isfinite(f.sog_m_s)) {
      const double dt = static_cast<double>(f.t_utc_ns - prev_t) * 1e-9;
      if (dt > 0.0 && dt <= 5.0) {
        st.distance_m += 0.5 * (prev_sog + f.sog_m_s) * dt;
        st.time_with_fix_s += dt;
      }
    }
    prev_t = f.t_utc_ns;
    prev_sog = f.sog_m_s;
    return true;
  });
  st.sog_max_m_s = max_sog;
  st.sog_mean_m_s = st.time_with_fix_s > 0.0 ? st.distance_m / st.time_with_fix_s
                                             : std::numeric_limits<double>::quiet_NaN();
  return st;
}

std::vector<WearableSample> Store::wearable_track(const std::string& athlete_id,
                                                  std::uint64_t from_ns, std::uint64_t to_ns,
                                                  std::size_t limit) {
  const ReadLease reader(*this);
  Stmt q(reader.db(),
         "SELECT t_utc_ns, seq, steps, cadence_spm, gait, pose, x_m, y_m, heading_deg, "
         "distance_m FROM wearable WHERE athlete_id = ? AND t_utc_ns >= ? AND "
         "t_utc_ns <= ? ORDER BY t_utc_ns LIMIT ?");
  q.bind(1, athlete_id)
      .bind_u(2, from_ns)
      .bind_u(3, to_ns)
      .bind(4, static_cast<std::int64_t>(limit));
  std::vector<WearableSample> out;
  while (q.step()) {
    WearableSample w;
    w.athlete_id = athlete_id;
    w.t_utc_ns = q.u64(0);
    w.seq = q.u64(1);
    w.steps = static_cast<std::uint32_t>(q.i64(2));
    w.cadence_spm = q.dbl(3);
    w.gait = q.text(4);
    w.pose = q.text(5);
    w.x_m = q.dbl(6);
    w.y_m = q.dbl(7);
    w.heading_deg = q.dbl(8);
    w.distance_m = q.dbl(9);
    out.push_back(std::move(w));
  }
  return out;
}

void Store::flush() {
  std::unique_lock lock(mutex_);
  const std::uint64_t target = enqueued_;
  const std::uint64_t fix_target = fixes_enqueued_;
  const std::uint64_t wind_target = wind_enqueued_;
  cv_.notify_all();
  flushed_cv_.wait_for(lock, std::chrono::seconds(10), [&] {
    return (processed_ >= target && fixes_processed_ >= fix_target &&
            wind_processed_ + dropped_wind_ >= wind_target) ||
           stopping_ ||
           backoff_.count() > 0;
  });
}

void Store::writer_loop() {
  std::vector<AttitudeSample> batch;
  std::vector<WearableSample> wearable;
  std::vector<FixSample> fixes;
  std::vector<WindSample> wind;
  // Commits keep a fixed rate: each is due one interval after the previous one was due, not after
  // it finished. A sample then waits at most the interval plus the commit that takes it, whatever
  // the one before took (a WAL checkpoint, a slow disk); one that overran is followed at once.
  auto due = std::chrono::steady_clock::now() + config_.commit_interval;
  for (;;) {
    bool stop = false;
    {
      std::unique_lock lock(mutex_);
      cv_.wait_until(lock, due, [this] { return stopping_; });
      due = std::max(due + config_.commit_interval, std::chrono::steady_clock::now());
      stop = stopping_;
      // While commits fail, wait out the backoff (the queue keeps what came): retrying the whole
      // backlog every commit interval only burns CPU. At stop, one last attempt regardless.
      if (!stop && backoff_.count() > 0 && std::chrono::steady_clock::now() < retry_at_) continue;
      batch.swap(queue_);
      wearable.swap(wearable_queue_);
      fixes.swap(fix_queue_);
      wind.swap(wind_queue_);
      in_hand_ = {batch.size(), wearable.size(), fixes.size(), wind.size()};
    }
    // Every kind is kept and retried when its write fails (a full disk): wearables and fixes
    // have no backfill, so a batch dropped here would be lost for good.
    bool failed = false;
    const bool work = !wearable.empty() || !fixes.empty() || !batch.empty() || !wind.empty();
    // Attitude first: its commit is what the boats' receipts and the crash window are about.
    if (!batch.empty()) {
      const std::size_t n = batch.size();
      if (commit(batch)) {
        std::lock_guard lock(mutex_);
        in_hand_.attitude = 0;
        processed_ += n;
      } else {
        failed = true;
      }
    }
    if (!wearable.empty()) {
      if (commit_wearable(wearable)) {
        std::lock_guard lock(mutex_);
        in_hand_.wearable = 0;
      } else {
        failed = true;
        requeue(wearable, wearable_queue_, dropped_wearable_, in_hand_.wearable);
      }
    }
    wearable.clear();
    if (!fixes.empty()) {
      const std::size_t n = fixes.size();
      if (commit_fixes(fixes)) {
        std::lock_guard lock(mutex_);
        in_hand_.fixes = 0;
        fixes_processed_ += n;
      } else {
        failed = true;
        requeue(fixes, fix_queue_, dropped_fixes_, in_hand_.fixes);
      }
    }
    fixes.clear();
    if (!wind.empty()) {
      const std::size_t n = wind.size();
      if (commit_wind(wind)) {
        std::lock_guard lock(mutex_);
        in_hand_.wind = 0;
        wind_processed_ += n;
      } else {
        failed = true;
        requeue(wind, wind_queue_, dropped_wind_, in_hand_.wind);
      }
    }
    wind.clear();
    if (work) {
      std::lock_guard lock(mutex_);
      if (!failed) {
        backoff_ = std::chrono::milliseconds(0);
      } else {
        ++failed_commits_;
        backoff_ = std::min(std::max(2 * backoff_, config_.commit_interval),
                            std::max(config_.max_retry_interval, config_.commit_interval));
        retry_at_ = std::chrono::steady_clock::now() + backoff_;
      }
    }
    flushed_cv_.notify_all();
    batch.clear();
    if (config_.retention_days > 0.0 && std::chrono::steady_clock::now() >= next_retention_) {
      apply_retention();
      next_retention_ = std::chrono::steady_clock::now() + std::chrono::hours(1);
    }
    if (stop) return;
  }
}

bool Store::commit(std::vector<AttitudeSample>& batch) {
  std::lock_guard db_lock(db_mutex_);
  std::uint64_t inserted = 0;
  batch_received_ns_ =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  try {
    exec(db_, "BEGIN");
    // In time order per boat, so sessions grow forward.
    std::sort(batch.begin(), batch.end(), [](const AttitudeSample& a, const AttitudeSample& b) {
      return a.boat_id != b.boat_id ? a.boat_id < b.boat_id : a.t_utc_ns < b.t_utc_ns;
    });
    const AttitudeSample* run_of_id = nullptr;  // the id is looked up once per run in a row
    const std::string* recorded = nullptr;
    TierFold tiers;
    for (const auto& s : batch) {
      if (!run_of_id || run_of_id->boat_id != s.boat_id || run_of_id->boot_id != s.boot_id) {
        recorded = &recorded_id(s);
        run_of_id = &s;
      }
      const std::string& id = *recorded;
      sqlite3_reset(insert_);
      sqlite3_bind_text(insert_, 1, id.c_str(), static_cast<int>(id.size()), SQLITE_TRANSIENT);
      sqlite3_bind_int64(insert_, 2, static_cast<sqlite3_int64>(s.t_utc_ns));
      // Boot ids are random 64-bit numbers: stored as their two's-complement int64.
      bind_fields(insert_, 3, kAttitudeFields, s);
      if (sqlite3_step(insert_) != SQLITE_DONE) throw StoreError(sqlite3_errmsg(db_));
      if (sqlite3_changes(db_) == 1) {  // a duplicate (re-sent sample) changes nothing
        ++inserted;
        extend_session(id, s.t_utc_ns);
        tiers.add(id, s.t_utc_ns, s.heel_deg, s.pitch_deg, s.heading_deg);
      }
    }
    Stmt up(db_,
            "UPDATE sessions SET start_ns = ?, end_ns = ?, samples = ?, received_ns = ? "
            "WHERE id = ?");
    for (const auto& boat : dirty_sessions_) {
      const SessionInfo& sess = open_sessions_.at(boat);
      up.reset();
      up.bind_u(1, sess.start_ns).bind_u(2, sess.end_ns).bind(3, sess.samples);
      up.bind_u(4, batch_received_ns_).bind(5, sess.id);
      up.step();
    }
    dirty_sessions_.clear();
    tiers.write(db_);
    for (const auto& boat : backfilled_) merge_sessions(boat);
    backfilled_.clear();
    exec(db_, "COMMIT");
    // On disk now: these samples may be acknowledged to their boats.
    for (const auto& s : batch) track_receipt(s);
    std::lock_guard lock(mutex_);
    committed_ += inserted;
    last_error_.clear();
    return true;
  } catch (const StoreError& e) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    // A full disk: give the WAL's space back (a checkpoint moves its pages into the database and
    // truncates it), which may be just what the next attempt needs.
    sqlite3_wal_checkpoint_v2(db_, nullptr, SQLITE_CHECKPOINT_TRUNCATE, nullptr, nullptr);
    open_sessions_.clear();  // reload from disk: the rolled-back changes are gone
    dirty_sessions_.clear();
    backfilled_.clear();
    try {
      load_aliases();  // an alias made in this batch went with it; the next attempt makes it again
    } catch (const StoreError&) {
      aliases_.clear();
    }
    // Keep the batch for the next attempt (disk full, locked): nothing already received is lost
    // while the process lives.
    std::lock_guard lock(mutex_);
    last_error_ = e.what();
    in_hand_.attitude = 0;
    queue_.insert(queue_.begin(), batch.begin(), batch.end());
    if (queue_.size() > config_.max_backlog) {
      // What came while this batch was out: the newest beyond the bound go (never acknowledged).
      const std::size_t excess = queue_.size() - config_.max_backlog;
      queue_.resize(config_.max_backlog);
      dropped_ += excess;
      processed_ += excess;  // dealt with, for flush()
    }
    return false;
  }
}

void Store::write_transaction(const std::function<void(sqlite3*)>& work) {
  std::lock_guard db_lock(db_mutex_);
  exec(db_, "BEGIN IMMEDIATE");
  try {
    work(db_);
    exec(db_, "COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    open_sessions_.clear();
    throw;
  }
  open_sessions_.clear();
}

void Store::read(const std::function<void(sqlite3*)>& work) {
  const ReadLease reader(*this);
  work(reader.db());
}

void Store::extend_session(const std::string& boat_id, std::uint64_t t_ns) {
  const auto gap = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(config_.session_gap).count());
  auto it = open_sessions_.find(boat_id);
  if (it == open_sessions_.end()) {
    Stmt q(db_,
           "SELECT id, boat_id, start_ns, end_ns, samples FROM sessions WHERE boat_id = ? "
           "ORDER BY end_ns DESC LIMIT 1");
    q.bind(1, boat_id);
    if (q.step()) it = open_sessions_.emplace(boat_id, session_from(q)).first;
  }
  if (it != open_sessions_.end()) {
    SessionInfo& s = it->second;
    if (t_ns + gap >= s.start_ns && t_ns <= s.end_ns + gap) {
      s.start_ns = std::min(s.start_ns, t_ns);
      s.end_ns = std::max(s.end_ns, t_ns);
      ++s.samples;
      dirty_sessions_.insert(boat_id);
      return;
    }
    if (t_ns < s.start_ns) {
      // Backfill older than the latest session: extend the session it belongs to, if any. It may
      // close the gap to its neighbour: merge_sessions() joins them before the commit.
      backfilled_.insert(boat_id);
      Stmt q(db_,
             "UPDATE sessions SET start_ns = MIN(start_ns, ?1), end_ns = MAX(end_ns, ?1), "
             "samples = samples + 1, received_ns = ?4 WHERE id = (SELECT id FROM sessions "
             "WHERE boat_id = ?2 AND start_ns <= ?1 + ?3 AND end_ns + ?3 >= ?1 LIMIT 1)");
      q.bind_u(1, t_ns).bind(2, boat_id).bind_u(3, gap).bind_u(4, batch_received_ns_);
      q.step();
      if (sqlite3_changes(db_) == 1) return;
      Stmt ins(db_,
               "INSERT INTO sessions (boat_id, start_ns, end_ns, samples, received_ns) "
               "VALUES (?,?,?,1,?)");
      ins.bind(1, boat_id).bind_u(2, t_ns).bind_u(3, t_ns).bind_u(4, batch_received_ns_);
      ins.step();
      return;
    }
  }
  Stmt ins(db_,
           "INSERT INTO sessions (boat_id, start_ns, end_ns, samples, received_ns) "
           "VALUES (?,?,?,0,?)");
  ins.bind(1, boat_id).bind_u(2, t_ns).bind_u(3, t_ns).bind_u(4, batch_received_ns_);
  ins.step();
  open_sessions_[boat_id] = {sqlite3_last_insert_rowid(db_), boat_id, t_ns, t_ns, 1};
  dirty_sessions_.insert(boat_id);
}

void Store::merge_sessions(const std::string& boat_id) {
  // A link cut longer than the session gap splits a boat's activity in two: live data after the
  // cut opens a new session before the backfill of the cut arrives. Once the backfill has closed
  // the gap, the two are one session again.
  const auto gap = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(config_.session_gap).count());
  std::vector<SessionInfo> all;
  {
    Stmt q(db_,
           "SELECT id, boat_id, start_ns, end_ns, samples FROM sessions WHERE boat_id = ? "
           "ORDER BY start_ns");
    q.bind(1, boat_id);
    while (q.step()) all.push_back(session_from(q));
  }
  for (std::size_t i = 1; i < all.size(); ++i) {
    SessionInfo& prev = all[i - 1];
    const SessionInfo& next = all[i];
    if (next.start_ns > prev.end_ns + gap) continue;
    prev.end_ns = std::max(prev.end_ns, next.end_ns);
    prev.samples += next.samples;
    Stmt up(db_,
            "UPDATE sessions SET end_ns = ?1, samples = ?2, received_ns = MAX(received_ns, "
            "(SELECT received_ns FROM sessions WHERE id = ?4)) WHERE id = ?3");
    up.bind_u(1, prev.end_ns).bind(2, prev.samples).bind(3, prev.id).bind(4, next.id);
    up.step();
    Stmt del(db_, "DELETE FROM sessions WHERE id = ?");
    del.bind(1, next.id);
    del.step();
    if (auto it = open_sessions_.find(boat_id);
        it != open_sessions_.end() && (it->second.id == next.id || it->second.id == prev.id))
      it->second = prev;
    all[i] = prev;  // the merged session is the one the next comparison extends
  }
}

void Store::note_stored(std::map<std::pair<std::string, std::uint64_t>, Receipt>& receipts,
                        const char* table, const std::string& boat_id, std::uint64_t boot_id,
                        std::uint64_t seq, std::chrono::steady_clock::time_point now) {
  auto [it, added] = receipts.try_emplace({boat_id, boot_id});
  Receipt& r = it->second;
  if (added) {
    // A run not seen since this shore started: what is already stored counts (restart).
    // Under the boat's id, and its run's alias if it has one (a second node's run).
    const auto alias = aliases_.find({boat_id, boot_id});
    Stmt q(db_, (std::string("SELECT seq FROM ") + table +
                 " WHERE boat_id IN (?1, ?3) AND boot_id = ?2 ORDER BY seq")
                    .c_str());
    q.bind(1, boat_id).bind(2, static_cast<std::int64_t>(boot_id));
    q.bind(3, alias == aliases_.end() ? boat_id : alias->second);
    while (q.step()) {
      const std::uint64_t stored = q.u64(0);
      if (stored == r.acked + 1) {
        r.acked = stored;
      } else if (stored > r.acked + 1) {
        r.ahead.insert(stored);
      }
    }
  }
  r.touched = now;
  // The next in line (nearly every sample) moves the mark without touching the set, which
  // otherwise allocated and freed a node per sample.
  if (seq == r.acked + 1) {
    r.acked = seq;
  } else if (seq > r.acked) {
    r.ahead.insert(seq);
  }
  while (!r.ahead.empty() && *r.ahead.begin() <= r.acked + 1) {
    r.acked = std::max(r.acked, *r.ahead.begin());
    r.ahead.erase(r.ahead.begin());
  }
}

// A run silent this long has nothing more coming: its receipt is dropped (and rebuilt from disk
// if the boat sends it again), so the receipts published each second stay few.
constexpr auto kReceiptIdle = std::chrono::minutes(2);

void Store::track_fix_receipt(const FixSample& f) {
  if (f.seq == 0) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(receipts_mutex_);
  note_stored(fix_receipts_, "fixes", f.boat_id, f.boot_id, f.seq, now);
  if (++receipt_updates_ % 1024 == 0)
    std::erase_if(fix_receipts_,
                  [&](const auto& e) { return now - e.second.touched > kReceiptIdle; });
}

void Store::track_receipt(const AttitudeSample& s) {
  if (s.seq == 0) return;
  constexpr auto kIdle = kReceiptIdle;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(receipts_mutex_);
  note_stored(receipts_, "attitude", s.boat_id, s.boot_id, s.seq, now);
  RunSpan& span = spans_[s.boat_id][s.boot_id];
  span.min_t_ns = std::min(span.min_t_ns, s.t_utc_ns);
  span.max_t_ns = std::max(span.max_t_ns, s.t_utc_ns);
  span.touched = now;
  if (++receipt_updates_ % 1024 == 0) {
    std::erase_if(receipts_, [&](const auto& e) { return now - e.second.touched > kIdle; });
    std::erase_if(fix_receipts_, [&](const auto& e) { return now - e.second.touched > kIdle; });
    for (auto& [boat, runs] : spans_)
      std::erase_if(runs, [&](const auto& e) { return now - e.second.touched > kIdle; });
    std::erase_if(spans_, [](const auto& e) { return e.second.empty(); });
  }
}

void Store::load_aliases() {
  aliases_.clear();
  Stmt q(db_, "SELECT boat_id, boot_id, alias FROM boat_aliases");
  while (q.step()) aliases_[{q.text(0), q.u64(1)}] = q.text(2);
}

std::string Store::duplicate_alias(const std::string& boat_id, std::uint64_t boot_id) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "%06llx", static_cast<unsigned long long>(boot_id & 0xFFFFFF));
  return boat_id.substr(0, 25) + "-" + hex;
}

const std::string& Store::recorded_id(const AttitudeSample& s) {
  const auto key = std::make_pair(s.boat_id, s.boot_id);
  if (const auto it = aliases_.find(key); it != aliases_.end()) return it->second;
  // Another run storing the same span at once (at_once), started earlier: this is the second
  // node's run.
  const auto now = std::chrono::steady_clock::now();
  bool second = false;
  {
    std::lock_guard lock(receipts_mutex_);
    const auto boat = spans_.find(s.boat_id);
    if (boat == spans_.end()) return s.boat_id;
    const auto mine = boat->second.find(s.boot_id);
    if (mine == boat->second.end()) return s.boat_id;
    for (const auto& [boot, span] : boat->second) {
      if (boot != s.boot_id && at_once(span, mine->second, now) &&
          span.min_t_ns < mine->second.min_t_ns && !aliases_.count({s.boat_id, boot}))
        second = true;
    }
  }
  if (!second) return s.boat_id;
  const std::string alias = duplicate_alias(s.boat_id, s.boot_id);
  Stmt save(db_, "INSERT OR REPLACE INTO boat_aliases (boat_id, boot_id, alias) VALUES (?, ?, ?)");
  save.bind(1, s.boat_id).bind(2, static_cast<std::int64_t>(s.boot_id)).bind(3, alias);
  save.step();  // in the batch's transaction: rolled back with it if the batch fails
  std::fprintf(stderr,
               "shore_server: two nodes publish as '%s': run %llx is recorded as '%s' from now\n",
               s.boat_id.c_str(), static_cast<unsigned long long>(s.boot_id), alias.c_str());
  return aliases_.emplace(key, alias).first->second;
}

bool Store::at_once(const RunSpan& a, const RunSpan& b, std::chrono::steady_clock::time_point now) {
  // Both runs storing within this window, and their spans overlapping by more than a second: a
  // restarted boat's runs follow each other in time, two boats with one id interleave.
  constexpr auto kWindow = std::chrono::seconds(30);
  constexpr std::uint64_t kOverlap_ns = 1'000'000'000;
  if (now - a.touched > kWindow || now - b.touched > kWindow) return false;
  const std::uint64_t lo = std::max(a.min_t_ns, b.min_t_ns);
  const std::uint64_t hi = std::min(a.max_t_ns, b.max_t_ns);
  return hi > lo && hi - lo > kOverlap_ns;
}

std::vector<Store::DuplicateId> Store::duplicate_ids() const {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(receipts_mutex_);
  std::vector<DuplicateId> out;
  for (const auto& [boat, runs] : spans_) {
    for (auto a = runs.begin(); a != runs.end(); ++a) {
      for (auto b = std::next(a); b != runs.end(); ++b)
        if (at_once(a->second, b->second, now)) out.push_back({boat, a->first, b->first});
    }
  }
  return out;
}

std::vector<Store::Ack> Store::acks() const {
  std::lock_guard lock(receipts_mutex_);
  std::vector<Ack> out;
  for (const auto& [key, r] : receipts_) out.push_back({key.first, key.second, r.acked});
  return out;
}

std::vector<Store::Ack> Store::fix_acks() const {
  std::lock_guard lock(receipts_mutex_);
  std::vector<Ack> out;
  for (const auto& [key, r] : fix_receipts_) out.push_back({key.first, key.second, r.acked});
  return out;
}

void Store::apply_retention() {
  const double now_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  const double cutoff_s = now_s - config_.retention_days * 86400.0;
  if (cutoff_s <= 0) return;
  const auto cutoff = static_cast<std::uint64_t>(cutoff_s * 1e9);
  std::lock_guard db_lock(db_mutex_);
  try {
    exec(db_, "BEGIN");
    // Age is the shore's: when the session last received a sample (rows from before the column
    // existed have 0 there and go by their end time). A boat's clock days behind makes old-looking
    // samples that arrived today; they stay.
    struct Gone {
      std::int64_t id;
      std::string boat_id;
      std::uint64_t start_ns, end_ns;
    };
    std::vector<Gone> gone;
    {
      Stmt q(db_,
             "SELECT id, boat_id, start_ns, end_ns FROM sessions WHERE "
             "(CASE WHEN received_ns > 0 THEN received_ns ELSE end_ns END) < ?");
      q.bind_u(1, cutoff);
      while (q.step()) gone.push_back({q.i64(0), q.text(1), q.u64(2), q.u64(3)});
    }
    Stmt del_session(db_, "DELETE FROM sessions WHERE id = ?");
    // The session's samples, except any a kept session of the boat covers.
    Stmt del_samples(db_,
                     "DELETE FROM attitude WHERE boat_id = ?1 AND t_utc_ns BETWEEN ?2 AND ?3 "
                     "AND NOT EXISTS (SELECT 1 FROM sessions k WHERE k.boat_id = ?1 AND "
                     "k.start_ns <= attitude.t_utc_ns AND k.end_ns >= attitude.t_utc_ns)");
    Stmt del_fixes(db_,
                   "DELETE FROM fixes WHERE boat_id = ?1 AND t_utc_ns BETWEEN ?2 AND ?3 "
                   "AND NOT EXISTS (SELECT 1 FROM sessions k WHERE k.boat_id = ?1 AND "
                   "k.start_ns <= fixes.t_utc_ns AND k.end_ns >= fixes.t_utc_ns)");
    Stmt del_wind(db_,
                  "DELETE FROM wind WHERE boat_id = ?1 AND t_utc_ns BETWEEN ?2 AND ?3 "
                  "AND NOT EXISTS (SELECT 1 FROM sessions k WHERE k.boat_id = ?1 AND "
                  "k.start_ns <= wind.t_utc_ns AND k.end_ns >= wind.t_utc_ns)");
    for (const auto& g : gone) {
      del_wind.reset();
      del_wind.bind(1, g.boat_id).bind_u(2, g.start_ns).bind_u(3, g.end_ns).step();
      del_session.reset();
      del_session.bind(1, g.id).step();
      del_samples.reset();
      del_samples.bind(1, g.boat_id).bind_u(2, g.start_ns).bind_u(3, g.end_ns).step();
      del_fixes.reset();
      del_fixes.bind(1, g.boat_id).bind_u(2, g.start_ns).bind_u(3, g.end_ns).step();
      rebuild_tiers(db_, g.boat_id, g.start_ns, g.end_ns);
    }
    Stmt e(db_, "DELETE FROM alarm_events WHERE phase = 'cleared' AND cleared_ns < ?");
    e.bind_u(1, cutoff).step();
    exec(db_, "COMMIT");
    open_sessions_.clear();
    dirty_sessions_.clear();
  } catch (const StoreError& e) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    open_sessions_.clear();
    dirty_sessions_.clear();
    std::lock_guard lock(mutex_);
    last_error_ = std::string("retention: ") + e.what();
  }
}

std::vector<SessionInfo> Store::sessions(const std::optional<std::string>& boat_id,
                                         std::uint64_t from_ns, std::uint64_t to_ns) {
  const ReadLease reader(*this);
  const std::string sql = std::string("SELECT ") + kSessionColumns +
                          " FROM sessions WHERE (?1 IS NULL OR boat_id = ?1) AND end_ns >= ?2 "
                          "AND start_ns <= ?3 ORDER BY start_ns DESC LIMIT 10000";
  Stmt q(reader.db(), sql.c_str());
  if (boat_id) q.bind(1, *boat_id);
  q.bind_u(2, from_ns).bind_u(3, to_ns);
  std::vector<SessionInfo> out;
  while (q.step()) out.push_back(session_from(q));
  return out;
}

std::optional<SessionInfo> Store::session(std::int64_t id) {
  const ReadLease reader(*this);
  const std::string sql = std::string("SELECT ") + kSessionColumns + " FROM sessions WHERE id = ?";
  Stmt q(reader.db(), sql.c_str());
  q.bind(1, id);
  if (!q.step()) return std::nullopt;
  return session_from(q);
}

bool Store::knows_boat(const std::string& boat_id) {
  const ReadLease reader(*this);
  Stmt q(reader.db(), "SELECT 1 FROM sessions WHERE boat_id = ? LIMIT 1");
  q.bind(1, boat_id);
  return q.step();
}

std::vector<AttitudeRow> Store::attitude_page(const std::string& boat_id, std::uint64_t after_ns,
                                              std::uint64_t to_ns, std::size_t limit) {
  const ReadLease reader(*this);
  static const std::string kSql =
      "SELECT " + select_columns(kAttitudeFields) +
      " FROM attitude WHERE boat_id = ? AND t_utc_ns > ? AND t_utc_ns <= ? ORDER BY t_utc_ns "
      "LIMIT ?";
  Stmt q(reader.db(), kSql.c_str());
  q.bind(1, boat_id).bind_u(2, after_ns).bind_u(3, to_ns).bind(4, static_cast<std::int64_t>(limit));
  std::vector<AttitudeRow> out;
  out.reserve(limit);
  while (q.step()) out.push_back(row_from(q));
  return out;
}

void Store::visit_attitude(const std::string& boat_id, std::uint64_t from_ns, std::uint64_t to_ns,
                           const std::function<bool(const AttitudeRow&)>& visit, std::size_t page) {
  if (from_ns > to_ns) return;
  // attitude_page is exclusive of its start: step back one ns (times are > 0).
  std::uint64_t after = from_ns == 0 ? 0 : from_ns - 1;
  for (;;) {
    const auto rows = attitude_page(boat_id, after, to_ns, page);
    for (const auto& r : rows)
      if (!visit(r)) return;
    if (rows.size() < page) return;
    after = rows.back().t_utc_ns;
  }
}

std::vector<TierBucket> Store::attitude_tier(const std::string& boat_id, std::uint64_t width_s,
                                             std::uint64_t from_ns, std::uint64_t to_ns) {
  std::vector<TierBucket> out;
  if (from_ns > to_ns) return out;
  const std::uint64_t w_ns = width_s * 1000000000ULL;
  const ReadLease reader(*this);
  Stmt q(reader.db(),
         "SELECT bucket, n, e0_t, e0_heel, e0_pitch, e0_hdg, e1_t, e1_heel, e1_pitch, e1_hdg, "
         "e2_t, e2_heel, e2_pitch, e2_hdg, e3_t, e3_heel, e3_pitch, e3_hdg FROM attitude_tier "
         "WHERE boat_id = ? AND width_s = ? AND bucket BETWEEN ? AND ? ORDER BY bucket");
  q.bind(1, boat_id).bind_u(2, width_s).bind_u(3, from_ns / w_ns);
  q.bind_u(4, std::min<std::uint64_t>(to_ns, std::numeric_limits<std::int64_t>::max()) / w_ns);
  while (q.step()) {
    TierBucket b;
    b.start_ns = q.u64(0) * w_ns;
    b.n = q.i64(1);
    for (int e = 0; e < 4; ++e) {
      AttitudeRow& r = b.extremes[static_cast<std::size_t>(e)];
      r.t_utc_ns = q.u64(2 + 4 * e);
      r.heel_deg = q.dbl(3 + 4 * e);
      r.pitch_deg = q.dbl(4 + 4 * e);
      r.heading_deg = q.dbl(5 + 4 * e);
    }
    out.push_back(b);
  }
  return out;
}

std::int64_t Store::count(const std::string& boat_id) {
  const ReadLease reader(*this);
  Stmt q(reader.db(), "SELECT COUNT(*) FROM attitude WHERE boat_id = ?");
  q.bind(1, boat_id);
  return q.step() ? q.i64(0) : 0;
}

void Store::save_rules(const std::vector<AlarmRule>& rules) {
  std::lock_guard db_lock(db_mutex_);
  try {
    exec(db_, "BEGIN IMMEDIATE");
    exec(db_, "DELETE FROM alarm_rules");
    Stmt ins(db_,
             "INSERT INTO alarm_rules (id, position, scope, quantity, min_deg, max_deg, "
             "hold_s, hysteresis_deg, level, enabled) VALUES (?,?,?,?,?,?,?,?,?,?)");
    std::int64_t pos = 0;
    for (const auto& r : rules) {
      ins.reset();
      ins.bind(1, r.id).bind(2, pos++).bind(3, r.scope).bind(4, std::string(to_string(r.quantity)));
      ins.bind(5, r.min_deg).bind(6, r.max_deg).bind(7, r.hold_s).bind(8, r.hysteresis_deg);
      ins.bind(9, std::string(to_string(r.level))).bind(10, std::int64_t{r.enabled ? 1 : 0});
      ins.step();
    }
    exec(db_, "COMMIT");
  } catch (const StoreError&) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::vector<AlarmRule> Store::load_rules() {
  const ReadLease reader(*this);
  Stmt q(reader.db(),
         "SELECT id, scope, quantity, min_deg, max_deg, hold_s, hysteresis_deg, level, "
         "enabled FROM alarm_rules ORDER BY position");
  std::vector<AlarmRule> out;
  while (q.step()) {
    AlarmRule r;
    r.id = q.text(0);
    r.scope = q.text(1);
    r.quantity = parse_quantity(q.text(2)).value_or(AlarmQuantity::kHeel);
    r.min_deg = q.dbl(3);
    r.max_deg = q.dbl(4);
    r.hold_s = q.dbl(5);
    r.hysteresis_deg = q.dbl(6);
    r.level = parse_level(q.text(7)).value_or(AlarmLevel::kWarn);
    r.enabled = q.i64(8) != 0;
    out.push_back(r);
  }
  return out;
}

void Store::save_event(const AlarmEvent& e) {
  std::lock_guard db_lock(db_mutex_);
  Stmt q(db_,
         "INSERT OR REPLACE INTO alarm_events (id, boat_id, rule_id, level, phase, raised_ns, "
         "acknowledged_ns, silenced_ns, cleared_ns, value_deg, message) "
         "VALUES (?,?,?,?,?,?,?,?,?,?,?)");
  q.bind_u(1, e.id).bind(2, e.boat_id).bind(3, e.rule_id).bind(4, std::string(to_string(e.level)));
  q.bind(5, std::string(to_string(e.phase))).bind_u(6, e.raised_ns).bind_u(7, e.acknowledged_ns);
  q.bind_u(8, e.silenced_ns).bind_u(9, e.cleared_ns).bind(10, e.value_deg).bind(11, e.message);
  q.step();
}

std::vector<AlarmEvent> Store::events(const EventFilter& f) {
  const ReadLease reader(*this);
  const std::string sql = std::string("SELECT ") + kEventColumns +
                          " FROM alarm_events WHERE (?1 IS NULL OR boat_id = ?1) AND raised_ns "
                          ">= ?2 AND raised_ns <= ?3 AND (?4 = 0 OR phase != 'cleared') "
                          "ORDER BY raised_ns DESC, id DESC LIMIT ?5";
  Stmt q(reader.db(), sql.c_str());
  if (f.boat_id) q.bind(1, *f.boat_id);
  q.bind_u(2, f.from_ns).bind_u(3, f.to_ns).bind(4, std::int64_t{f.active_only ? 1 : 0});
  q.bind(5, static_cast<std::int64_t>(f.limit));
  std::vector<AlarmEvent> out;
  while (q.step()) out.push_back(event_from(q));
  return out;
}

std::optional<AlarmEvent> Store::event(std::uint64_t id) {
  const ReadLease reader(*this);
  const std::string sql =
      std::string("SELECT ") + kEventColumns + " FROM alarm_events WHERE id = ?";
  Stmt q(reader.db(), sql.c_str());
  q.bind_u(1, id);
  if (!q.step()) return std::nullopt;
  return event_from(q);
}

std::uint64_t Store::max_event_id() {
  const ReadLease reader(*this);
  Stmt q(reader.db(), "SELECT COALESCE(MAX(id), 0) FROM alarm_events");
  return q.step() ? q.u64(0) : 0;
}

std::uint64_t Store::fixes_committed() const {
  std::lock_guard lock(mutex_);
  return fixes_committed_;
}

std::uint64_t Store::committed() const {
  std::lock_guard lock(mutex_);
  return committed_;
}

StoreHealth Store::health() const {
  std::lock_guard lock(mutex_);
  StoreHealth h;
  h.failing = backoff_.count() > 0;
  h.backlog = queue_.size() + in_hand_.attitude;
  h.dropped = dropped_;
  h.wearable_backlog = wearable_queue_.size() + in_hand_.wearable;
  h.fix_backlog = fix_queue_.size() + in_hand_.fixes;
  h.wearable_dropped = dropped_wearable_;
  h.fixes_dropped = dropped_fixes_;
  h.wind_backlog = wind_queue_.size() + in_hand_.wind;
  h.wind_dropped = dropped_wind_;
  h.failed_commits = failed_commits_;
  if (h.failing)
    h.retry_in_s = std::max(
        0.0, std::chrono::duration<double>(retry_at_ - std::chrono::steady_clock::now()).count());
  h.last_error = last_error_;
  return h;
}

std::string Store::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

}  // namespace telltale::shore
