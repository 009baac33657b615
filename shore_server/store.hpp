#pragma once
/// \file
/// The shore's recording in SQLite (WAL): attitude samples, GNSS fixes, sessions, alarm rules and
/// events. A session is a boat and a time span; its fixes are the boat's fixes in that span.
/// Attitude and fixes each have their receipts (acks(), fix_acks()): per boat run, how far every
/// record is stored, from which the boats backfill what is missing.
///
/// Writes: the DDS listener queues samples (never blocks on disk); one writer thread commits them
/// in batches at a fixed rate. Durability window: a sample is on disk at most `commit_interval`
/// (default 250 ms) plus the commit's own time after it arrived; a crash loses at most that
/// window, which the boats' backfill refills. A sample already stored (same boat, same UTC time)
/// is kept once (INSERT OR IGNORE), so re-sent samples merge without duplicates. Alarm rules and
/// events are written synchronously: an acknowledgement is on disk before the request that made
/// it is answered.
///
/// Sessions: continuous activity of one boat. A sample within `session_gap` of a boat's session
/// extends it; otherwise it starts a new one.
///
/// Retention (`retention_days`) goes by the shore's clock: a session goes once no sample has
/// arrived into it for that long (`received_ns`, the shore's arrival time), whatever the boat's
/// clock said: a boat without a time fix can be days behind, and its samples are still new.
///
/// A failing disk (full, read-only): the batch stays queued and is retried with exponential
/// backoff (commit_interval doubling up to `max_retry_interval`), the WAL is checkpointed to give
/// space back, and the queue is bounded (`max_backlog`: later samples are dropped and counted).
/// Nothing dropped or left unsaved at stop was acknowledged, so the boats still hold it in their
/// session logs and resend it when the shore's receipts show it missing. health() says all this.
///
/// Reads go through a second, read-only connection, so a long export never blocks ingest; range
/// reads page through the data (keyset on time), so memory does not grow with the range.

#include <sqlite3.h>

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "fleet.hpp"
#include "store_error.hpp"
#include "telltale/fusion/alarm_engine.hpp"

namespace telltale::shore {

struct StoreConfig {
  std::string path;
  std::chrono::milliseconds commit_interval{250};
  std::chrono::seconds session_gap{60};
  double retention_days = 0.0;                          ///< 0: keep everything
  std::size_t max_backlog = 200000;                     ///< samples queued while commits fail
  std::chrono::milliseconds max_retry_interval{30000};  ///< backoff cap while commits fail
};

/// The writer's state for /healthz.
struct StoreHealth {
  bool failing = false;                ///< the latest commit failed
  std::size_t backlog = 0;             ///< samples queued, not committed
  std::uint64_t dropped = 0;           ///< samples refused: backlog full (never acknowledged)
  std::size_t wearable_backlog = 0;    ///< wearable samples queued, kept while writes fail
  std::size_t fix_backlog = 0;         ///< GNSS fixes queued, kept while writes fail
  std::uint64_t wearable_dropped = 0;  ///< beyond the bound while failing: lost (no backfill)
  std::uint64_t fixes_dropped = 0;     ///< the same for fixes
  std::size_t wind_backlog = 0;        ///< wind readings queued, kept while writes fail
  std::uint64_t wind_dropped = 0;      ///< the same for wind readings
  std::uint64_t failed_commits = 0;
  double retry_in_s = 0.0;  ///< until the next attempt while failing
  std::string last_error;
};

struct SessionInfo {
  std::int64_t id = 0;
  std::string boat_id;
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;
  std::int64_t samples = 0;
};

/// Widths of the chart tiers' time buckets, finest first (Store::attitude_tier).
inline constexpr std::array<std::uint64_t, 2> kTierWidths_s = {1, 16};

/// One time bucket of a chart tier: how many samples it holds and the four that a thinned chart
/// keeps (lowest heel, highest heel, lowest pitch, highest pitch; only time, heel, pitch and
/// heading are set).
struct TierBucket {
  std::uint64_t start_ns = 0;
  std::int64_t n = 0;
  std::array<AttitudeRow, 4> extremes{};
};

/// What the fixes of a span say about the sailing.
struct FixStats {
  std::int64_t fixes = 0;   ///< with a position
  double distance_m = 0.0;  ///< distance sailed: SOG integrated over time (see fix_stats)
  double time_with_fix_s = 0.0;
  double sog_mean_m_s = 0.0;  ///< distance / time with a fix; NaN without fixes
  double sog_max_m_s = 0.0;   ///< NaN without fixes
};

struct EventFilter {
  std::optional<std::string> boat_id;
  std::uint64_t from_ns = 0;
  std::uint64_t to_ns = UINT64_MAX;
  bool active_only = false;
  std::size_t limit = 1000;
};

class Store {
 public:
  /// Opens or creates the database and its schema. Throws StoreError.
  explicit Store(StoreConfig config);
  /// Commits what is queued, then closes (a clean close leaves no -wal/-shm files).
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  /// Queues one sample for the next batch (never blocks on disk).
  void enqueue(const AttitudeSample& sample);
  /// Queues one wearable sample (committed with the next batch).
  void enqueue(const WearableSample& sample);
  /// An athlete's stored track in [from_ns, to_ns], oldest first, at most `limit` samples.
  [[nodiscard]] std::vector<WearableSample> wearable_track(const std::string& athlete_id,
                                                           std::uint64_t from_ns,
                                                           std::uint64_t to_ns, std::size_t limit);
  /// Queues one GNSS fix (committed with the next batch).
  void enqueue(const FixSample& fix);
  /// Queues one wind instrument reading (committed with the next batch, kept and retried when
  /// the write fails, as fixes are).
  void enqueue(const WindSample& wind);
  /// The boat's fixes with a position in [from_ns, to_ns], oldest first. More than `max_points`
  /// are thinned evenly in time to max_points (first and last kept).
  [[nodiscard]] std::vector<FixSample> track(const std::string& boat_id, std::uint64_t from_ns,
                                             std::uint64_t to_ns, std::size_t max_points);
  /// One page of fixes with a position after `after_ns` (exclusive) up to `to_ns`.
  [[nodiscard]] std::vector<FixSample> fix_page(const std::string& boat_id, std::uint64_t after_ns,
                                                std::uint64_t to_ns, std::size_t limit);
  /// Calls `visit` for every fix with a position of the boat in [from_ns, to_ns], in time order.
  void visit_fixes(const std::string& boat_id, std::uint64_t from_ns, std::uint64_t to_ns,
                   const std::function<bool(const FixSample&)>& visit, std::size_t page = 2000);
  /// The boat's wind instrument readings in [from_ns, to_ns], oldest first, at most `limit`
  /// (evenly thinned beyond it, first and last kept). Written by imports (ImportStore).
  [[nodiscard]] std::vector<WindSample> wind(const std::string& boat_id, std::uint64_t from_ns,
                                             std::uint64_t to_ns, std::size_t limit);
  /// Distance sailed and speeds over [from_ns, to_ns].
  [[nodiscard]] FixStats fix_stats(const std::string& boat_id, std::uint64_t from_ns,
                                   std::uint64_t to_ns);
  /// Waits (up to 10 s) until everything queued before the call is committed.
  void flush();

  // --- reads -------------------------------------------------------------------------------
  [[nodiscard]] std::vector<SessionInfo> sessions(const std::optional<std::string>& boat_id,
                                                  std::uint64_t from_ns, std::uint64_t to_ns);
  [[nodiscard]] std::optional<SessionInfo> session(std::int64_t id);
  /// True if the boat has any stored session.
  [[nodiscard]] bool knows_boat(const std::string& boat_id);
  /// Calls `visit` for every stored sample of the boat in [from_ns, to_ns], in time order, until
  /// it returns false. Pages through the data `page` rows at a time.
  void visit_attitude(const std::string& boat_id, std::uint64_t from_ns, std::uint64_t to_ns,
                      const std::function<bool(const AttitudeRow&)>& visit,
                      std::size_t page = 2000);
  /// One page of samples after `after_ns` (exclusive) up to `to_ns`: for streamed exports.
  [[nodiscard]] std::vector<AttitudeRow> attitude_page(const std::string& boat_id,
                                                       std::uint64_t after_ns, std::uint64_t to_ns,
                                                       std::size_t limit);
  [[nodiscard]] std::int64_t count(const std::string& boat_id);
  /// The boat's chart tier of `width_s` (one of kTierWidths_s): every bucket that overlaps
  /// [from_ns, to_ns], in time order. Kept as samples are stored; reads one row per bucket.
  [[nodiscard]] std::vector<TierBucket> attitude_tier(const std::string& boat_id,
                                                      std::uint64_t width_s, std::uint64_t from_ns,
                                                      std::uint64_t to_ns);

  // --- alarms (synchronous) ----------------------------------------------------------------
  void save_rules(const std::vector<AlarmRule>& rules);
  [[nodiscard]] std::vector<AlarmRule> load_rules();
  void save_event(const AlarmEvent& event);
  [[nodiscard]] std::vector<AlarmEvent> events(const EventFilter& filter);
  [[nodiscard]] std::optional<AlarmEvent> event(std::uint64_t id);
  [[nodiscard]] std::uint64_t max_event_id();

  /// Per boat and run (the current one, and earlier ones the boat is delivering from its log):
  /// the highest seq of that run with every sample up to it stored.
  struct Ack {
    std::string boat_id;
    std::uint64_t boot_id;
    std::uint64_t acked_seq;
  };
  [[nodiscard]] std::vector<Ack> acks() const;
  /// The same for the GNSS fixes: per boat and run, the highest fix seq with every fix up to it
  /// stored (a fix stored twice, live and backfilled, is one row: same boat, same time).
  [[nodiscard]] std::vector<Ack> fix_acks() const;

  /// Two runs of one boat id storing samples of the same time span, both within the last
  /// `kDuplicateWindow`: two nodes configured with one id (a restart or an earlier run's delivery
  /// never overlaps the new run in time). Flagged, and kept apart: from the moment the store sees
  /// the overlap (about a second of the later run's samples), the later run is recorded under
  /// its own id, duplicate_alias() (stored, so its backfill lands there after a restart too).
  struct DuplicateId {
    std::string boat_id;
    std::uint64_t boot_a;
    std::uint64_t boot_b;
  };
  [[nodiscard]] std::vector<DuplicateId> duplicate_ids() const;
  /// The id under which a second node's run of `boat_id` is recorded: the id cut to 25
  /// characters, '-' and the run's low 24 bits in hex (a valid id of at most 32 characters).
  [[nodiscard]] static std::string duplicate_alias(const std::string& boat_id,
                                                   std::uint64_t boot_id);

  /// Runs `work` on the writer connection inside one transaction (BEGIN IMMEDIATE), the live
  /// writer waiting meanwhile: committed when `work` returns, rolled back when it throws (the
  /// exception goes on). The cached open sessions are re-read from disk afterwards, as `work` may
  /// have changed sessions. For imports: a whole file is stored, or nothing of it.
  void write_transaction(const std::function<void(sqlite3*)>& work);
  /// Runs `work` on one of the read-only connections.
  void read(const std::function<void(sqlite3*)>& work);
  [[nodiscard]] std::chrono::seconds session_gap() const { return config_.session_gap; }

  [[nodiscard]] std::uint64_t committed() const;
  /// GNSS fixes written (re-sent duplicates included: INSERT OR IGNORE counts them too).
  [[nodiscard]] std::uint64_t fixes_committed() const;
  [[nodiscard]] StoreHealth health() const;
  /// Last error of the writer thread, empty if none.
  [[nodiscard]] std::string last_error() const;

 private:
  void writer_loop();
  /// Commits a batch; on failure puts it back in the queue and returns false.
  bool commit(std::vector<AttitudeSample>& batch);
  /// Each false when the write failed (the caller requeues the batch).
  /// One transaction on the writer's connection: `write`, COMMIT, then `committed` (still on
  /// the connection: it may read). False, everything rolled back and the error kept, when
  /// either throws a StoreError.
  bool transaction(const char* what, const std::function<void()>& write,
                   const std::function<void()>& committed = {});
  /// Queues `item` unless the queue is at the backlog bound (then counted in `dropped`); true
  /// when queued.
  template <class T>
  bool push_bounded(std::vector<T>& queue, const T& item, std::uint64_t& dropped) {
    if (queue.size() >= config_.max_backlog) {
      ++dropped;
      return false;
    }
    queue.push_back(item);
    return true;
  }
  bool commit_wearable(const std::vector<WearableSample>& batch);
  bool commit_fixes(const std::vector<FixSample>& batch);
  bool commit_wind(const std::vector<WindSample>& batch);
  /// A failed batch back at the head of its queue, the queue bounded by max_backlog (the oldest
  /// beyond it dropped and counted in `dropped`).
  /// `in_hand` (the batch's count in in_hand_) goes to zero in the same step.
  template <class T>
  void requeue(std::vector<T>& batch, std::vector<T>& queue, std::uint64_t& dropped,
               std::size_t& in_hand);
  void extend_session(const std::string& boat_id, std::uint64_t t_ns);
  void apply_retention();
  /// Shore time (ns since 1970) of the batch being committed: the sessions' arrival time.
  std::uint64_t batch_received_ns_ = 0;
  void track_receipt(const AttitudeSample& sample);
  void track_fix_receipt(const FixSample& fix);
  /// Joins this boat's sessions that backfill has brought within the session gap of each other.
  void merge_sessions(const std::string& boat_id);
  std::set<std::string> backfilled_;  ///< boats with backfill older than their open session

  struct Receipt {
    std::uint64_t acked = 0;
    std::set<std::uint64_t> ahead;                  ///< stored seqs beyond a gap
    std::chrono::steady_clock::time_point touched;  ///< when a sample of this run last came
  };
  mutable std::mutex receipts_mutex_;
  /// (boat, run) -> receipt: the boat's current run and earlier runs it is still delivering.
  std::map<std::pair<std::string, std::uint64_t>, Receipt> receipts_;
  /// The same for the fixes, from the fixes table (under receipts_mutex_, writer thread).
  std::map<std::pair<std::string, std::uint64_t>, Receipt> fix_receipts_;
  /// Counts `seq` of (boat, run) as stored in `receipts`; a run not seen since this shore started
  /// first learns what `table` already holds of it. Caller holds receipts_mutex_.
  void note_stored(std::map<std::pair<std::string, std::uint64_t>, Receipt>& receipts,
                   const char* table, const std::string& boat_id, std::uint64_t boot_id,
                   std::uint64_t seq, std::chrono::steady_clock::time_point now);
  std::uint64_t receipt_updates_ = 0;  ///< under receipts_mutex_
  struct RunSpan {
    std::uint64_t min_t_ns = UINT64_MAX;
    std::uint64_t max_t_ns = 0;
    std::chrono::steady_clock::time_point touched;
  };
  /// Two runs of one id storing the same time span at once (see duplicate_ids()).
  static bool at_once(const RunSpan& a, const RunSpan& b,
                      std::chrono::steady_clock::time_point now);
  /// boat -> run -> the time span it stored (under receipts_mutex_), for duplicate_ids().
  std::map<std::string, std::map<std::uint64_t, RunSpan>> spans_;
  /// (boat, run) -> the id its samples are recorded under: a second node's run (writer thread;
  /// loaded from and saved to the boat_aliases table).
  std::map<std::pair<std::string, std::uint64_t>, std::string> aliases_;
  /// The id `s` is recorded under: its boat's, or its run's alias once that run is seen to
  /// overlap an earlier run of the same id (writer thread, inside a commit).
  const std::string& recorded_id(const AttitudeSample& s);
  void load_aliases();

  StoreConfig config_;
  sqlite3* db_ = nullptr;  ///< writer connection (samples, sessions, alarms)
  sqlite3_stmt* insert_ = nullptr;
  std::mutex db_mutex_;  ///< serialises use of db_
  /// Read-only connections for queries. SQLite's WAL lets them read side by side and beside the
  /// writer, so a long export no longer queues every chart request behind it: a query takes an
  /// idle one (ReadLease) or waits for one.
  static constexpr std::size_t kReaders = 4;
  class ReadLease;
  std::vector<sqlite3*> readers_;
  std::vector<sqlite3*> idle_readers_;
  std::mutex readers_mutex_;
  std::condition_variable reader_idle_;
  std::map<std::string, SessionInfo> open_sessions_;  ///< latest session per boat (writer only)
  std::set<std::string> dirty_sessions_;              ///< open sessions changed in this batch

  mutable std::mutex mutex_;  ///< guards the queue and the counters
  std::condition_variable cv_;
  std::condition_variable flushed_cv_;
  std::vector<AttitudeSample> queue_;
  std::vector<WearableSample> wearable_queue_;
  std::vector<FixSample> fix_queue_;
  std::vector<WindSample> wind_queue_;
  /// What the writer has taken out of each queue and not yet stored or put back: still the
  /// backlog, so health() counts it (a retry of a full disk holds the whole backlog here).
  struct InHand {
    std::size_t attitude = 0, wearable = 0, fixes = 0, wind = 0;
  } in_hand_;
  std::uint64_t wind_enqueued_ = 0, wind_processed_ = 0;
  std::uint64_t dropped_wind_ = 0;  ///< readings dropped (backlog full, or requeued past it)
  std::uint64_t fixes_enqueued_ = 0;
  std::uint64_t fixes_processed_ = 0;
  std::uint64_t fixes_committed_ = 0;
  std::uint64_t dropped_wearable_ = 0;
  std::uint64_t dropped_fixes_ = 0;  ///< fixes the writer has dealt with (flush waits for them)
  std::uint64_t enqueued_ = 0;
  std::uint64_t processed_ = 0;  ///< enqueued samples the writer has dealt with
  std::uint64_t committed_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t failed_commits_ = 0;
  std::chrono::milliseconds backoff_{0};            ///< 0 while commits succeed
  std::chrono::steady_clock::time_point retry_at_;  ///< next attempt while failing
  bool stopping_ = false;
  std::string last_error_;
  std::chrono::steady_clock::time_point next_retention_;
  std::thread writer_;
};

}  // namespace telltale::shore
