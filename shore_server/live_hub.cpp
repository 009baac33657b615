#include "live_hub.hpp"

#include <algorithm>

namespace telltale::shore {
namespace {
std::shared_ptr<const std::string> frame(const std::string& type, const std::string& data) {
  auto f = std::make_shared<std::string>();
  f->reserve(type.size() + data.size() + 16);
  *f += "event: ";
  *f += type;
  *f += "\ndata: ";
  *f += data;  // JSON from nlohmann::dump() has no raw newlines
  *f += "\n\n";
  return f;
}
}  // namespace

LiveHub::LiveHub(std::size_t max_clients, std::size_t max_events,
                 std::chrono::milliseconds frame_interval)
    : max_clients_(max_clients), max_events_(max_events), frame_interval_(frame_interval) {}

std::shared_ptr<LiveHub::Client> LiveHub::connect(std::optional<std::string> only_key) {
  std::lock_guard lock(mutex_);
  if (closed_ || clients_.size() >= max_clients_) return nullptr;
  auto client = std::make_shared<Client>();
  client->only_key_ = std::move(only_key);
  client->seen_version_ = version_;  // the stream starts with its own snapshot
  clients_.push_back(client);
  return client;
}

void LiveHub::disconnect(const std::shared_ptr<Client>& client) {
  std::lock_guard lock(mutex_);
  clients_.erase(std::remove(clients_.begin(), clients_.end(), client), clients_.end());
}

const std::string& LiveHub::LazyFrame::text() const {
  std::call_once(once_, [this] {
    text_ = *frame("sample", render_());
    render_ = nullptr;  // what it captured (a boat's view) is not needed any more
  });
  return text_;
}

void LiveHub::publish_sample(const std::string& key, std::function<std::string()> render) {
  auto f = std::make_shared<const LazyFrame>(std::move(render));
  std::lock_guard lock(mutex_);
  Latest& l = latest_[key];
  l.version = ++version_;
  l.frame = std::move(f);
}

void LiveHub::forget(const std::string& key) {
  std::lock_guard lock(mutex_);
  latest_.erase(key);
}

void LiveHub::publish_event(const std::string& type, const std::string& data,
                            const std::string& key) {
  const auto f = frame(type, data);
  {
    std::lock_guard lock(mutex_);
    for (auto& c : clients_) {
      if (c->only_key_ && *c->only_key_ != key) continue;
      if (c->events_.size() >= max_events_) {
        c->events_.pop_front();
        ++c->dropped_events_;
      }
      c->events_.push_back(f);
    }
  }
  cv_.notify_all();
}

bool LiveHub::pending(const Client& c) const {
  if (!c.events_.empty() || c.dropped_events_ > 0) return true;
  if (version_ <= c.seen_version_) return false;
  if (!c.only_key_) return true;
  const auto it = latest_.find(*c.only_key_);
  return it != latest_.end() && it->second.version > c.seen_version_;
}

std::string LiveHub::wait(Client& client, std::chrono::milliseconds timeout, bool& closed) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + timeout;
  std::unique_lock lock(mutex_);
  // Pace: one batch per frame interval at most (a stop still wakes us).
  cv_.wait_until(lock, std::min(client.next_frame_, deadline), [this] { return closed_; });
  // Samples do not notify: look again every frame interval; events wake us at once.
  while (!closed_ && !pending(client)) {
    const auto now = Clock::now();
    if (now >= deadline) break;
    cv_.wait_until(lock, std::min(deadline, now + frame_interval_),
                   [&] { return closed_ || !client.events_.empty(); });
  }
  closed = closed_;
  std::string out;
  if (closed || !pending(client)) return out;
  client.next_frame_ = Clock::now() + frame_interval_;
  if (client.dropped_events_ > 0) {
    // The client was too slow to take every event: tell it, so it can refetch what it missed.
    out +=
        *frame("overflow", "{\"dropped_events\":" + std::to_string(client.dropped_events_) + "}");
    client.dropped_events_ = 0;
  }
  for (const auto& e : client.events_) out += *e;
  client.events_.clear();
  // Under the lock only the list of what changed; the frames are rendered and joined after it.
  std::vector<std::shared_ptr<const LazyFrame>> changed;
  for (const auto& [key, l] : latest_) {
    if (l.version <= client.seen_version_) continue;
    if (client.only_key_ && *client.only_key_ != key) continue;
    changed.push_back(l.frame);
  }
  client.seen_version_ = version_;
  lock.unlock();
  for (const auto& f : changed) out += f->text();
  return out;
}

void LiveHub::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

std::size_t LiveHub::clients() const {
  std::lock_guard lock(mutex_);
  return clients_.size();
}

}  // namespace telltale::shore
