#pragma once
/// \file
/// Live push to dashboards (Server-Sent Events), built so that no number of slow or fast
/// dashboards can slow down ingest.
///
/// Samples: the hub keeps only the latest frame per key (boat); publishing replaces it under a
/// short lock and wakes nobody. Each client takes, at most once per frame interval (default
/// 40 ms = the boats' 25 Hz), every key that changed since its previous batch: a slow client skips
/// intermediate samples, it never queues them. Events (alarms, athletes) are queued per client
/// (bounded, the oldest dropped and reported as `overflow`) and wake the client at once.
///
/// A sample's frame is rendered lazily: publishing stores how to render it, and the first client
/// that sends it renders it (once; later clients share the text), outside the hub's lock. A boat
/// publishing at 25 Hz to dashboards that take 10 frames a second is rendered 10 times a second,
/// not 25, and the live worker that publishes never pays for JSON.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace telltale::shore {

class LiveHub {
 public:
  class Client;

  /// At most `max_clients` streams at once; at most `max_events` events wait per client.
  LiveHub(std::size_t max_clients, std::size_t max_events,
          std::chrono::milliseconds frame_interval = std::chrono::milliseconds(40));

  /// A new client, or nullptr when the hub is full or closed. With `only_key` set the client gets
  /// samples and events of that key (boat) alone (an athlete's dashboard).
  std::shared_ptr<Client> connect(std::optional<std::string> only_key = std::nullopt);
  void disconnect(const std::shared_ptr<Client>& client);

  /// Replaces the latest sample of `key`. `render` makes its JSON payload when a client first
  /// sends it (on that client's thread; it must not throw).
  void publish_sample(const std::string& key, std::function<std::string()> render);
  /// Drops the latest sample of `key` (a boat the fleet model forgot).
  void forget(const std::string& key);
  /// Queues an event of SSE type `type` about `key` for every client that may see it.
  void publish_event(const std::string& type, const std::string& data, const std::string& key);

  /// The next batch for `client` as SSE frames, waiting up to `timeout` for something to send
  /// (and at least until the client's next frame time). Empty on timeout. Sets `closed` when the
  /// hub is shutting down (the stream must end).
  std::string wait(Client& client, std::chrono::milliseconds timeout, bool& closed);

  /// Wakes every waiting client and refuses new ones.
  void close();
  [[nodiscard]] std::size_t clients() const;

 private:
  /// A sample's SSE frame, rendered by the first client that needs it.
  class LazyFrame {
   public:
    explicit LazyFrame(std::function<std::string()> render) : render_(std::move(render)) {}
    const std::string& text() const;

   private:
    mutable std::function<std::string()> render_;
    mutable std::once_flag once_;
    mutable std::string text_;
  };
  struct Latest {
    std::uint64_t version = 0;
    std::shared_ptr<const LazyFrame> frame;
  };
  [[nodiscard]] bool pending(const Client& c) const;

  std::size_t max_clients_;
  std::size_t max_events_;
  std::chrono::milliseconds frame_interval_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::map<std::string, Latest> latest_;
  std::uint64_t version_ = 0;
  std::vector<std::shared_ptr<Client>> clients_;
  bool closed_ = false;
};

class LiveHub::Client {
 private:
  friend class LiveHub;
  std::optional<std::string> only_key_;
  std::uint64_t seen_version_ = 0;  ///< samples up to this version were sent
  std::chrono::steady_clock::time_point next_frame_{};
  std::deque<std::shared_ptr<const std::string>> events_;
  std::size_t dropped_events_ = 0;
};

}  // namespace telltale::shore
