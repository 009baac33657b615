#pragma once
/// \file
/// WitMotion / JY901(B) / WT901 serial protocol (the module of seed 004): decoder, encoder and a
/// termios serial reader.
///
/// Wire format (WT901/JY901 manual, "standard protocol"): 11-byte packets
///   0x55, TYPE, D0L, D0H, D1L, D1H, D2L, D2H, D3L, D3H, SUM
/// with SUM = low byte of the sum of the first 10 bytes and Dn little-endian int16. Types and
/// scale factors:
///   0x51 acceleration   a = D/32768 * 16 g  (D0..D2 = x, y, z), D3 = temperature/100 degC
///   0x52 angular rate   w = D/32768 * 2000 deg/s, D3 = temperature (or voltage)/100
///   0x53 angle          roll, pitch, yaw = D/32768 * 180 deg, D3 = version
///   0x54 magnetometer   raw counts D0..D2; the manual gives no physical unit (it depends on the
///                       magnetometer chip); converted with `mag_uT_per_lsb` (default 0.1 uT,
///                       i.e. 1 mG per count, configurable), D3 = temperature/100
///   0x56 pressure/height  P = int32 (D0,D1) in Pa, H = int32 (D2,D3) in cm
/// Other types (0x50 time, 0x55 port, 0x57.. GPS, quaternion) are checked and skipped.
/// The 16 g / 2000 deg/s ranges are the module's defaults; other ranges are parameters.
///
/// Axes: the module's own x, y, z are passed through unchanged (the JY901B is FLU-like when
/// mounted flat with its x forward); mounting rotations belong to the caller.
///
/// Robustness: the decoder resynchronises on the next 0x55 after any garbage or bad checksum,
/// counts what it skipped, and never throws or reads out of bounds on any byte sequence.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::sensors {

/// One assembled WitMotion sample: everything the module sent in one output cycle.
struct WitSample {
  fusion::ImuSample imu;  ///< t_s = host receive time; acc m/s^2; gyro rad/s
  Eigen::Vector3d mag_uT = Eigen::Vector3d::Zero();
  Eigen::Vector3d angle_deg = Eigen::Vector3d::Zero();  ///< module's roll, pitch, yaw
  double pressure_pa = 0.0;
  double height_m = 0.0;
  double temperature_c = 0.0;
  bool has_gyro = false;
  bool has_mag = false;
  bool has_angle = false;
  bool has_pressure = false;
};

struct WitMotionParams {
  double acc_range_g = 16.0;
  double gyro_range_deg_s = 2000.0;
  double angle_range_deg = 180.0;
  double mag_uT_per_lsb = 0.1;
};

struct WitMotionStats {
  std::uint64_t frames = 0;         ///< packets with a good checksum
  std::uint64_t bad_checksum = 0;   ///< 0x55-framed packets whose checksum failed
  std::uint64_t skipped_bytes = 0;  ///< bytes discarded while looking for 0x55
  std::uint64_t unknown_type = 0;   ///< good packets of a type we do not use
  std::uint64_t samples = 0;        ///< samples handed to the callback
};

/// Byte-stream decoder. A sample is emitted once its cycle is complete: the decoder learns which
/// packet type ends the module's cycle (the one that precedes the next 0x51) and emits when it
/// arrives; before that, on the next 0x51. `flush()` emits a pending sample.
class WitMotionDecoder {
 public:
  using Params = WitMotionParams;
  using Callback = std::function<void(const WitSample&)>;
  explicit WitMotionDecoder(Callback callback, Params params = {});
  /// Feeds received bytes; `t_s` is their receive time (stamped on samples completed by them).
  void feed(std::span<const std::uint8_t> bytes, double t_s);
  void flush();
  [[nodiscard]] const WitMotionStats& stats() const { return stats_; }

 private:
  void packet(const std::uint8_t* p, double t_s);
  void emit();
  Callback callback_;
  Params params_;
  WitMotionStats stats_;
  std::array<std::uint8_t, 11> buf_{};
  std::size_t have_ = 0;
  WitSample pending_;
  bool pending_acc_ = false;
  int last_type_ = -1;  ///< type of the previous good packet
  int cycle_end_ = -1;  ///< learned type that ends a cycle
};

/// Encoder (tests, simulators): one packet, and a whole sample as the module would send it
/// (0x51, 0x52, 0x53, 0x54, 0x56; the optional parts only when present). Values are clamped to
/// the int16/int32 ranges.
[[nodiscard]] std::array<std::uint8_t, 11> encode_wit_packet(std::uint8_t type,
                                                             std::array<std::int16_t, 4> data);
[[nodiscard]] std::vector<std::uint8_t> encode_wit_sample(const WitSample& sample,
                                                          const WitMotionParams& params = {});

/// Serial port reader (termios raw 8N1, no flow control). Throws std::system_error when the
/// device cannot be opened or configured, std::invalid_argument for an unsupported baud rate.
class WitMotionSerial {
 public:
  WitMotionSerial(const std::string& device, int baud, WitMotionDecoder::Callback callback,
                  WitMotionParams params = {});
  ~WitMotionSerial();
  WitMotionSerial(const WitMotionSerial&) = delete;
  WitMotionSerial& operator=(const WitMotionSerial&) = delete;
  /// Waits up to `timeout_ms` for bytes and decodes what arrived. Returns false on end of file
  /// or a read error (the device went away), true otherwise.
  bool poll_once(int timeout_ms);
  /// Reads until `stop` becomes true or the device goes away.
  void run(const std::atomic<bool>& stop);
  [[nodiscard]] const WitMotionStats& stats() const { return decoder_.stats(); }

 private:
  int fd_ = -1;
  WitMotionDecoder decoder_;
};

}  // namespace telltale::sensors
