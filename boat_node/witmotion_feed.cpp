#include "witmotion_feed.hpp"

namespace telltale::boat {

WitMotionFeed::WitMotionFeed(const std::string& device_and_baud) {
  std::string device = device_and_baud;
  int baud = 9600;
  if (const auto at = device.find('@'); at != std::string::npos) {
    baud = std::stoi(device.substr(at + 1));
    device = device.substr(0, at);
  }
  port_ = std::make_unique<sensors::WitMotionSerial>(
      device, baud, [this](const sensors::WitSample& w) {
        if (!w.has_gyro) return;
        std::lock_guard lock(mutex_);
        queue_.push_back(w);
        if (queue_.size() > 1000) {
          queue_.pop_front();
          dropped_.fetch_add(1);
        }
        cv_.notify_one();
      });
  thread_ = std::thread([this] {
    port_->run(stop_);
    gone_ = true;
    cv_.notify_all();
  });
}

WitMotionFeed::~WitMotionFeed() {
  stop_ = true;
  thread_.join();
}

std::optional<sensors::WitSample> WitMotionFeed::next(const std::function<bool()>& stop) {
  std::unique_lock lock(mutex_);
  while (queue_.empty()) {
    if (stop() || gone_.load()) return std::nullopt;
    cv_.wait_for(lock, std::chrono::milliseconds(100));
  }
  sensors::WitSample s = queue_.front();
  queue_.pop_front();
  return s;
}

sensors::WitMotionStats WitMotionFeed::stats() const { return port_->stats(); }

}  // namespace telltale::boat
