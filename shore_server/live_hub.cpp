#include "live_hub.hpp"

#include <algorithm>

namespace telltale::shore {
namespace {
std::string frame(const std::string& type, const std::string& data) {
  std::string f;
  f.reserve(type.size() + data.size() + 16);
  f += "event: ";
  f += type;
  f += "\ndata: ";
  f += data;  // JSON from nlohmann::dump() has no raw newlines
  f += "\n\n";
  return f;
}
}  // namespace

LiveHub::LiveHub(std::size_t max_clients, std::size_t max_events)
    : max_clients_(max_clients), max_events_(max_events) {}

std::shared_ptr<LiveHub::Client> LiveHub::connect(std::optional<std::string> only_key) {
  std::lock_guard lock(mutex_);
  if (closed_ || clients_.size() >= max_clients_) return nullptr;
  auto client = std::make_shared<Client>();
  client->only_key_ = std::move(only_key);
  clients_.push_back(client);
  return client;
}

void LiveHub::disconnect(const std::shared_ptr<Client>& client) {
  std::lock_guard lock(mutex_);
  clients_.erase(std::remove(clients_.begin(), clients_.end(), client), clients_.end());
}

void LiveHub::publish_sample(const std::string& key, std::string data) {
  {
    std::lock_guard lock(mutex_);
    if (clients_.empty()) return;
    for (auto& c : clients_)
      if (!c->only_key_ || *c->only_key_ == key) c->latest_[key] = data;
  }
  cv_.notify_all();
}

void LiveHub::publish_event(const std::string& type, const std::string& data,
                            const std::string& key) {
  const std::string f = frame(type, data);
  {
    std::lock_guard lock(mutex_);
    if (clients_.empty()) return;
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

std::string LiveHub::wait(Client& client, std::chrono::milliseconds timeout, bool& closed) {
  std::unique_lock lock(mutex_);
  cv_.wait_for(lock, timeout,
               [&] { return closed_ || !client.latest_.empty() || !client.events_.empty(); });
  closed = closed_;
  std::string out;
  if (client.dropped_events_ > 0) {
    // The client was too slow to take every event: tell it, so it can refetch what it missed.
    out += frame("overflow", "{\"dropped_events\":" + std::to_string(client.dropped_events_) + "}");
    client.dropped_events_ = 0;
  }
  for (auto& e : client.events_) out += e;
  client.events_.clear();
  for (auto& [key, data] : client.latest_) out += frame("sample", data);
  client.latest_.clear();
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
