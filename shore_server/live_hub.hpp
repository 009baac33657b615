#pragma once
/// \file
/// Live push to dashboards (Server-Sent Events). Each client has its own mailbox: the latest
/// sample per boat (a slow client skips intermediate samples, it never queues them) and a bounded
/// queue of events (alarms, stale/live changes) that are never coalesced. Frames are serialised
/// once per publish, not once per client.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
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
  LiveHub(std::size_t max_clients, std::size_t max_events);

  /// A new client, or nullptr when the hub is full or closed. With `only_key` set the client gets
  /// samples and events of that key (boat) alone (an athlete's dashboard).
  std::shared_ptr<Client> connect(std::optional<std::string> only_key = std::nullopt);
  void disconnect(const std::shared_ptr<Client>& client);

  /// Replaces the pending sample of `key` for every client. `data` is the JSON payload.
  void publish_sample(const std::string& key, std::string data);
  /// Queues an event of SSE type `type` about `key` for every client that may see it (the oldest
  /// is dropped when a client's queue is full).
  void publish_event(const std::string& type, const std::string& data, const std::string& key);

  /// Waits up to `timeout` for anything pending and returns it as SSE frames; empty on timeout.
  /// Sets `closed` when the hub is shutting down (the stream must end).
  std::string wait(Client& client, std::chrono::milliseconds timeout, bool& closed);

  /// Wakes every waiting client and refuses new ones.
  void close();
  [[nodiscard]] std::size_t clients() const;

 private:
  std::size_t max_clients_;
  std::size_t max_events_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::shared_ptr<Client>> clients_;
  bool closed_ = false;
};

class LiveHub::Client {
 private:
  friend class LiveHub;
  std::optional<std::string> only_key_;
  std::map<std::string, std::string> latest_;     ///< key -> payload of the newest sample
  std::deque<std::string> events_;                ///< ready SSE frames
  std::size_t dropped_events_ = 0;
};

}  // namespace telltale::shore
