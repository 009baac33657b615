#include "backfill.hpp"

#include <algorithm>
#include <cstdio>
#include <type_traits>

namespace telltale::boat {

namespace {
constexpr std::int64_t kReceiptSilence_ns = 3'000'000'000;  ///< three missed receipts

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

template <class Codec>
BasicBackfiller<Codec>::BasicBackfiller(BackfillConfig config, BasicSessionLogReader<Codec> reader,
                                        std::function<bool(const Record&)> send)
    : config_(config), reader_(std::move(reader)), send_(std::move(send)) {
  progress_ns_.store(steady_ns());
  thread_ = std::thread([this] { run(); });
}

template <class Codec>
double BasicBackfiller<Codec>::seconds_since_progress() const {
  return static_cast<double>(steady_ns() - progress_ns_.load()) * 1e-9;
}

template <class Codec>
BasicBackfiller<Codec>::~BasicBackfiller() {
  stop_.store(true);
  cv_.notify_all();
  thread_.join();
}

template <class Codec>
void BasicBackfiller<Codec>::on_ack(std::uint64_t boot_id, std::uint64_t acked_seq,
                                    bool new_shore) {
  // Receipts come every second; after a silence (a cut link, a shore restart) the shore is back
  // and the range it missed goes at once instead of at the next resend_after.
  const std::int64_t now_ns = steady_ns();
  const std::int64_t prev_ns = last_ack_ns_.exchange(now_ns);
  if (new_shore || (prev_ns != 0 && now_ns - prev_ns > kReceiptSilence_ns))
    force_resend_.store(true);
  shore_seen_.store(true);
  if (boot_id == config_.boot_id) {
    const std::uint64_t prev = acked_.exchange(acked_seq);
    if (acked_seq > prev) progress_ns_.store(now_ns);
    if (acked_seq < prev) {
      // The shore holds less than it said before (a fresh or replaced database, a restore): its
      // receipt is the truth. Resend from there, in order, once; the receipt then climbs as the
      // start of the run arrives (the shore already holds the tail).
      // At most once per resend_after: two shores on one domain, one of them empty, would
      // otherwise have the run resent at every receipt.
      progress_ns_.store(now_ns);
      const auto every_ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(config_.resend_after).count();
      const std::int64_t last_follow = followed_down_ns_.load();
      if (last_follow == 0 || now_ns - last_follow >= every_ns) {
        followed_down_ns_.store(now_ns);
        force_resend_.store(true);
      }
    }
  }
  cv_.notify_all();
}

template <class Codec>
std::uint64_t BasicBackfiller<Codec>::send_range(std::uint64_t first, std::uint64_t last) {
  constexpr std::uint64_t kChunk = 250;
  const auto chunk_period = std::chrono::milliseconds(
      static_cast<long>(1000 * kChunk / std::max<std::size_t>(config_.max_per_second, 1)));
  std::uint64_t sent_through = first - 1;
  for (std::uint64_t from = first; from <= last && !stop_.load(); from += kChunk) {
    const auto started = std::chrono::steady_clock::now();
    for (const auto& r : reader_.read(from, std::min(last, from + kChunk - 1))) {
      if (!send_(r)) {  // the shore went away again: the next receipt decides
        send_failures_.fetch_add(1);
        return sent_through;
      }
      resent_.fetch_add(1);
      sent_through = r.seq;
    }
    std::unique_lock lock(mutex_);
    cv_.wait_until(lock, started + chunk_period, [this] { return stop_.load(); });
  }
  return last;
}

template <class Codec>
void BasicBackfiller<Codec>::run() {
  std::uint64_t last_acked = 0;
  auto acked_moved_at = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point full_resend_at{};
  while (!stop_.load()) {
    {
      std::unique_lock lock(mutex_);
      cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stop_.load(); });
    }
    if (stop_.load() || !shore_seen_.load()) continue;
    // No receipt for a while: the shore does not hear this boat (link cut, shore down). Resending
    // into the void would only fill the link the moment it returns; the first receipt after the
    // silence sends the missing range at once.
    if (steady_ns() - last_ack_ns_.load() > kReceiptSilence_ns) continue;
    if (force_resend_.exchange(false)) sent_through_ = 0;
    const std::uint64_t published = published_.load();
    const std::uint64_t acked = acked_.load();
    const auto now = std::chrono::steady_clock::now();
    if (acked != last_acked) {
      last_acked = acked;
      acked_moved_at = now;
    }
    const std::uint64_t lag = draining_.load() ? 0 : config_.lag;
    if (published <= acked + lag) continue;
    const std::uint64_t last = published - lag;
    std::uint64_t first = acked + 1;
    // What was sent and not yet acknowledged is on its way: send only what is new, unless the
    // receipt has not moved for resend_after (the link was cut, the shore restarted): then all
    // of it again, at most once per resend_after. The timer is the receipt's, not the last send:
    // while the boat sails, new samples are sent every round and would otherwise postpone the
    // resend for as long as the boat sails.
    if (sent_through_ >= first) {
      const bool stalled = now - acked_moved_at >= config_.resend_after &&
                           now - full_resend_at >= config_.resend_after;
      if (stalled) {
        full_resend_at = now;
      } else {
        first = sent_through_ + 1;
        if (first > last) continue;
      }
    }
    sent_through_ = send_range(first, last);
  }
}

template <class Codec>
bool BasicBackfiller<Codec>::drain(std::chrono::milliseconds quiet,
                                   std::chrono::milliseconds patience) {
  // Nothing published, nothing to hand over: a boat without a GNSS fix (no receiver, no data)
  // has no fix receipt to wait for, and the shore sends none for a run it has no fix of.
  if (published_.load() == 0) return true;
  draining_.store(true);
  force_resend_.store(true);  // the run thread may resend at once
  const auto started = std::chrono::steady_clock::now();
  const auto complete = [this] { return shore_seen_.load() && acked_.load() >= published_.load(); };
  std::unique_lock lock(mutex_);
  for (;;) {
    if (complete()) return true;
    const auto now = std::chrono::steady_clock::now();
    const auto heard_ago = std::chrono::nanoseconds(steady_ns() - last_ack_ns_.load());
    if (now - started >= patience || (now - started >= quiet && heard_ago >= quiet)) return false;
    cv_.wait_for(lock, std::chrono::milliseconds(100));
  }
}

template <class Codec>
BasicEarlierRuns<Codec>::BasicEarlierRuns(std::filesystem::path dir, std::string boat_id,
                                          std::uint64_t current_boot, std::chrono::hours max_age,
                                          Send send, std::function<void(const std::string&)> report,
                                          std::chrono::seconds give_up)
    : dir_(std::move(dir)),
      boat_id_(std::move(boat_id)),
      runs_(undelivered_runs<Codec>(dir_, boat_id_, current_boot, max_age)),
      send_(std::move(send)),
      report_(std::move(report)),
      give_up_(give_up) {
  pending_.store(runs_.size());
  if (!runs_.empty()) thread_ = std::thread([this] { run(); });
}

template <class Codec>
BasicEarlierRuns<Codec>::~BasicEarlierRuns() {
  stop_.store(true);
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

template <class Codec>
void BasicEarlierRuns<Codec>::on_ack(std::uint64_t boot_id, std::uint64_t acked_seq,
                                     bool new_shore) {
  std::lock_guard lock(mutex_);
  if (active_) active_->on_ack(boot_id, acked_seq, new_shore);
}

template <class Codec>
void BasicEarlierRuns<Codec>::run() {
  for (const std::uint64_t boot : runs_) {
    BasicSessionLogReader<Codec> reader(dir_, boat_id_, boot);
    const std::uint64_t last = reader.last_seq();
    {
      std::lock_guard lock(mutex_);
      active_ = std::make_unique<BasicBackfiller<Codec>>(
          BackfillConfig{boot, 0, 2500, std::chrono::milliseconds(5000)}, std::move(reader),
          [this, boot](const typename Codec::Record& r) { return send_(boot, r); });
      active_->on_published(last);
    }
    std::string outcome;
    for (;;) {
      std::unique_lock lock(mutex_);
      if (cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stop_.load(); }))
        break;
      const std::uint64_t acked = active_->acked();
      if (acked >= last) {
        outcome = "delivered";
        break;
      }
      if (active_->shore_seen() &&
          active_->seconds_since_progress() > std::chrono::duration<double>(give_up_).count()) {
        outcome = "given up at seq " + std::to_string(acked) + " (the log has a hole)";
        break;
      }
    }
    {
      std::lock_guard lock(mutex_);
      active_.reset();
    }
    if (outcome.empty()) return;  // stopping: the run stays pending for the next start
    mark_delivered<Codec>(dir_, boat_id_, boot);
    pending_.fetch_sub(1);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(boot));
    report_("earlier run " + std::string(hex) + " (" + std::to_string(last) + " " +
            (std::is_same_v<Codec, FixCodec> ? "fixes" : "samples") + "): " + outcome);
  }
}

template class BasicBackfiller<AttitudeCodec>;
template class BasicBackfiller<FixCodec>;
template class BasicEarlierRuns<AttitudeCodec>;
template class BasicEarlierRuns<FixCodec>;

}  // namespace telltale::boat
