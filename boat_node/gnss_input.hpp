#pragma once
/// \file
/// One GNSS receiver on a thread of its own: gpsd through libgps, or NMEA 0183 straight from a
/// serial port or a UDP port. Epochs go through the GnssGate; the node's loop takes the fixes,
/// and the wind instrument's MWV/MWD readings when the NMEA line carries them.
/// Specs (binding, tools rely on them):
///   gpsd[:HOST[:PORT]]          gpsd, default localhost:2947; reconnects when gpsd restarts
///   nmea:DEVICE[@BAUD]          serial, 4800 baud by default
///   nmea:udp:[ADDR:]PORT        UDP, bound to 127.0.0.1 unless ADDR is given

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gnss_gate.hpp"
#include "nmea.hpp"
#include "run_clock.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::boat {

struct GnssInputStats {
  GnssGateStats gate;
  sensors::NmeaReaderStats nmea;       ///< NMEA sources: sentences by outcome
  std::uint64_t gpsd_reconnects = 0;   ///< gpsd sources
  std::uint64_t queue_overflows = 0;   ///< fixes dropped because the node did not take them
  double clock_offset_s = 0.0;         ///< boat clock - GNSS time, NaN before a time came
  bool connected = false;              ///< gpsd: connected now; NMEA: the device is open
};

/// A wind instrument's reading off the NMEA line, with the boat clock of its arrival.
struct TimedWind {
  std::uint64_t t_utc_ns = 0;
  fusion::WindReading reading;
};

class GnssInput {
 public:
  /// Parses the spec and opens the source (throws std::invalid_argument for a bad spec,
  /// std::system_error when a device or port cannot be opened; a gpsd not running yet is not an
  /// error: the reader keeps trying). `clock` stamps each fix and wind reading at its arrival.
  GnssInput(const std::string& spec, RunClock clock, GnssGateParams params = {});
  ~GnssInput();
  GnssInput(const GnssInput&) = delete;
  GnssInput& operator=(const GnssInput&) = delete;

  /// Moves the fixes accepted since the last call into `out` (cleared first).
  void take(std::vector<GnssFix>& out);
  /// Moves the wind readings (MWV/MWD on an NMEA source) since the last call into `out`.
  void take_wind(std::vector<TimedWind>& out);
  [[nodiscard]] GnssInputStats stats() const;
  [[nodiscard]] const std::string& describe() const { return describe_; }
  /// The UDP port of an nmea:udp source (0 otherwise): for tests that pick port 0.
  [[nodiscard]] int port() const { return port_; }

 private:
  void on_epoch(const sensors::GnssReading& r);
  void run_nmea();
  void run_gpsd(const std::string& host, const std::string& port);

  std::string describe_;
  RunClock clock_;
  std::unique_ptr<sensors::NmeaStreamReader> nmea_;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  GnssGate gate_;
  std::deque<GnssFix> queue_;
  std::deque<TimedWind> wind_;
  std::uint64_t overflows_ = 0;
  std::uint64_t reconnects_ = 0;
  bool connected_ = false;
  std::thread thread_;
};

}  // namespace telltale::boat
