#pragma once
/// \file
/// N NMEA 0183 heading sensors (serial devices or UDP ports), each read on a thread of its own,
/// fused by the closed-loop heading fusion at the node's publish ticks.
/// Specs: "nmea:/dev/ttyUSB0" (4800 baud), "nmea:/dev/ttyUSB0@38400", "nmea:udp:10110" (bound to
/// 127.0.0.1), "nmea:udp:0.0.0.0:10110".

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "telltale/fusion/heading_fusion.hpp"

namespace telltale::boat {

class HeadingInput {
 public:
  /// Opens every source (throws std::system_error / std::invalid_argument) and starts reading.
  /// `variation_deg` (E positive) turns magnetic headings into true ones; NaN: magnetic-only
  /// sentences are ignored.
  HeadingInput(const std::vector<std::string>& specs, double variation_deg);
  ~HeadingInput();

  /// Fuses the readings received since the last tick; NaN until a sensor has spoken.
  double tick(std::chrono::steady_clock::time_point now);
  [[nodiscard]] std::uint32_t sensors_in_use() const;
  [[nodiscard]] bool degraded() const;  ///< a sensor is excluded or none agrees
  [[nodiscard]] std::size_t count() const { return readers_.size(); }
  /// The UDP port of source i (0 for serial): for tests that pick port 0.
  [[nodiscard]] int port(std::size_t i) const;

 private:
  struct Reader;
  std::vector<std::unique_ptr<Reader>> readers_;
  mutable std::mutex mutex_;
  fusion::HeadingReadingBuffer buffer_;
  fusion::HeadingFusion fusion_;
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  double variation_deg_;
  bool any_reading_ = false;
};

}  // namespace telltale::boat
