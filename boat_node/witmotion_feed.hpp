#pragma once
/// \file
/// A WitMotion/JY901 module on a serial port, read on a thread of its own and handed out one
/// sample at a time (for the boat node's IMU source and the wearable node). "DEVICE[@BAUD]".

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "witmotion.hpp"

namespace telltale::boat {

class WitMotionFeed {
 public:
  /// Opens the device (throws std::system_error). Default baud 9600 (the module's default).
  explicit WitMotionFeed(const std::string& device_and_baud);
  ~WitMotionFeed();
  WitMotionFeed(const WitMotionFeed&) = delete;
  WitMotionFeed& operator=(const WitMotionFeed&) = delete;

  /// The next sample with a gyro reading; nothing once `stop()` returns true or the device is
  /// gone. Keeps at most 1000 samples if the reader falls behind (oldest dropped, counted).
  std::optional<sensors::WitSample> next(const std::function<bool()>& stop);
  [[nodiscard]] sensors::WitMotionStats stats() const;
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(); }

 private:
  std::unique_ptr<sensors::WitMotionSerial> port_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> gone_{false};
  std::atomic<std::uint64_t> dropped_{0};
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<sensors::WitSample> queue_;
  std::thread thread_;
};

}  // namespace telltale::boat
