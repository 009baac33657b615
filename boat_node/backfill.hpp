#pragma once
/// \file
/// Backfill: resends from the session log what the shore's receipts say it does not have.
/// The same code for both record kinds (session_log.hpp): attitude on "telltale_boat_backfill"
/// against the receipts on "telltale_shore_ack", fixes on "telltale_boat_fix_backfill" against
/// "telltale_shore_fix_ack"; each kind has its own seq, so its own receipts and its own thread.
///
/// The shore acknowledges, per boat run, the highest seq up to which every sample is stored.
/// When the node is more than `lag` samples ahead of that receipt (the newest samples may still
/// be in flight), a thread of its own reads the missing range from the log and writes it on the
/// reliable backfill topic at a bounded rate; the same range is sent again only if the receipt
/// has not moved for `resend_after`, or at once when receipts resume after a silence or come from
/// a shore instance not heard before (a restart: what was in flight to the old one is gone). At
/// shutdown `drain()` sends up to the last sample and waits for the receipt. The sensor loop only
/// stores an atomic counter.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "session_log.hpp"

namespace telltale::boat {

struct BackfillConfig {
  std::uint64_t boot_id = 0;
  std::uint64_t lag = 50;             ///< samples left to the live path (2 s at 25 Hz)
  std::size_t max_per_second = 2500;  ///< resend rate limit
  std::chrono::milliseconds resend_after{5000};
};

template <class Codec>
class BasicBackfiller {
 public:
  using Record = typename Codec::Record;
  /// `send` writes one record on the backfill topic (returns false if it could not).
  BasicBackfiller(BackfillConfig config, BasicSessionLogReader<Codec> reader,
                  std::function<bool(const Record&)> send);
  ~BasicBackfiller();

  void on_published(std::uint64_t seq) { published_.store(seq); }
  /// A receipt for this boat, any run: each one shows the shore is there; one for this run sets
  /// acked(), downward too (a shore on a fresh database: the run is resent from its receipt).
  /// `new_shore` (a shore instance not heard before) resends the missing range at once, as does
  /// a receipt after a silence.
  void on_ack(std::uint64_t boot_id, std::uint64_t acked_seq, bool new_shore = false);
  /// Sends everything up to the last published sample and waits for the shore's receipt. Gives
  /// up after `quiet` if the shore has not been heard for `quiet` (a cut link, a shore gone: the
  /// log keeps the samples); while the shore is heard, or was heard within `quiet` (it may be
  /// restarting), waits up to `patience`. True if the shore has it all (at once when nothing
  /// was published).
  bool drain(std::chrono::milliseconds quiet, std::chrono::milliseconds patience);

  [[nodiscard]] std::uint64_t acked() const { return acked_.load(); }
  [[nodiscard]] std::uint64_t published() const { return published_.load(); }
  /// Seconds since a receipt for this run last moved acked() (or since construction).
  [[nodiscard]] double seconds_since_progress() const;
  [[nodiscard]] std::uint64_t resent() const { return resent_.load(); }
  /// Backfill writes that failed (the writer's history full: the shore not acknowledging).
  [[nodiscard]] std::uint64_t send_failures() const { return send_failures_.load(); }
  [[nodiscard]] bool shore_seen() const { return shore_seen_.load(); }

 private:
  void run();
  /// Returns the last seq written (first - 1 if none).
  std::uint64_t send_range(std::uint64_t first, std::uint64_t last);

  BackfillConfig config_;
  BasicSessionLogReader<Codec> reader_;
  std::function<bool(const Record&)> send_;
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> acked_{0};
  std::atomic<std::uint64_t> resent_{0};
  std::atomic<std::uint64_t> send_failures_{0};
  std::atomic<std::int64_t> last_ack_ns_{0};       ///< steady clock of the latest receipt
  std::atomic<std::int64_t> progress_ns_{0};       ///< steady clock of the latest move of acked_
  std::atomic<std::int64_t> followed_down_ns_{0};  ///< steady clock of the latest lower receipt
  std::atomic<bool> shore_seen_{false};
  std::atomic<bool> draining_{false};
  std::atomic<bool> force_resend_{false};
  std::atomic<bool> stop_{false};
  std::uint64_t sent_through_ = 0;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::thread thread_;
};

/// Delivers earlier runs of this boat whose log the shore never confirmed in full (the boat was
/// stopped out of reach, or the shore was down): one run at a time, oldest first, each through a
/// Backfiller of its own with no live lag. A run is done, and marked so in the log directory,
/// when the shore's receipt for it reaches the last seq on disk, or when the shore is heard but
/// its receipt has not moved for `give_up` (samples the disk policy deleted leave a hole the
/// receipt cannot pass).
template <class Codec>
class BasicEarlierRuns {
 public:
  using Send = std::function<bool(std::uint64_t boot_id, const typename Codec::Record&)>;
  /// `report` gets one line per finished run (from the delivery thread).
  /// Offers the runs of `undelivered_runs(dir, boat_id, current_boot, max_age)`.
  BasicEarlierRuns(std::filesystem::path dir, std::string boat_id, std::uint64_t current_boot,
                   std::chrono::hours max_age, Send send,
                   std::function<void(const std::string&)> report,
                   std::chrono::seconds give_up = std::chrono::seconds(60));
  ~BasicEarlierRuns();

  void on_ack(std::uint64_t boot_id, std::uint64_t acked_seq, bool new_shore);
  /// Runs not delivered yet (including the one in progress).
  [[nodiscard]] std::size_t pending() const { return pending_.load(); }

 private:
  void run();

  std::filesystem::path dir_;
  std::string boat_id_;
  std::vector<std::uint64_t> runs_;
  Send send_;
  std::function<void(const std::string&)> report_;
  std::chrono::seconds give_up_;
  std::atomic<std::size_t> pending_{0};
  std::atomic<bool> stop_{false};
  std::mutex mutex_;  ///< guards active_ (the DDS listener forwards receipts to it)
  std::condition_variable cv_;
  std::unique_ptr<BasicBackfiller<Codec>> active_;
  std::thread thread_;
};

using Backfiller = BasicBackfiller<AttitudeCodec>;
using FixBackfiller = BasicBackfiller<FixCodec>;
using EarlierRuns = BasicEarlierRuns<AttitudeCodec>;
using FixEarlierRuns = BasicEarlierRuns<FixCodec>;

}  // namespace telltale::boat
