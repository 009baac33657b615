#include "witmotion.hpp"

#include "serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace telltale::sensors {
namespace {

constexpr std::uint8_t kHeader = 0x55;
constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kDegToRad = M_PI / 180.0;

std::int16_t i16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] | (p[1] << 8)));
}
std::int32_t i32(const std::uint8_t* p) {
  const std::uint32_t u =
      static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
      (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
  return static_cast<std::int32_t>(u);
}
std::uint8_t checksum(const std::uint8_t* p) {
  unsigned sum = 0;
  for (int i = 0; i < 10; ++i) sum += p[i];
  return static_cast<std::uint8_t>(sum & 0xFFu);
}
std::int16_t to_i16(double v) {
  if (!std::isfinite(v)) return 0;
  return static_cast<std::int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
}
std::int32_t to_i32(double v) {
  if (!std::isfinite(v)) return 0;
  return static_cast<std::int32_t>(std::clamp(std::llround(v), -2147483648LL, 2147483647LL));
}

}  // namespace

WitMotionDecoder::WitMotionDecoder(Callback callback, Params params)
    : callback_(std::move(callback)), params_(params) {}

void WitMotionDecoder::feed(std::span<const std::uint8_t> bytes, double t_s) {
  for (const std::uint8_t b : bytes) {
    if (have_ == 0 && b != kHeader) {
      ++stats_.skipped_bytes;
      continue;
    }
    buf_[have_++] = b;
    if (have_ < buf_.size()) continue;
    if (checksum(buf_.data()) == buf_[10]) {
      have_ = 0;
      packet(buf_.data(), t_s);
      continue;
    }
    // Bad frame: drop its header byte and rescan the rest for the next 0x55.
    ++stats_.bad_checksum;
    std::size_t next = 1;
    while (next < buf_.size() && buf_[next] != kHeader) ++next;
    stats_.skipped_bytes += next;
    std::copy(buf_.begin() + static_cast<std::ptrdiff_t>(next), buf_.end(), buf_.begin());
    have_ = buf_.size() - next;
  }
}

void WitMotionDecoder::packet(const std::uint8_t* p, double t_s) {
  const int type = p[1];
  const std::uint8_t* d = p + 2;
  if (type == 0x51) {
    if (cycle_end_ < 0 && last_type_ >= 0 && last_type_ != 0x51) cycle_end_ = last_type_;
    if (pending_acc_) emit();  // the previous cycle ended without its learned last packet
  }
  ++stats_.frames;
  switch (type) {
    case 0x51: {
      const double k = params_.acc_range_g * kG / 32768.0;
      pending_.imu.acc_body_m_s2 = {k * i16(d), k * i16(d + 2), k * i16(d + 4)};
      pending_.temperature_c = i16(d + 6) / 100.0;
      pending_.imu.t_s = t_s;
      pending_acc_ = true;
      break;
    }
    case 0x52: {
      const double k = params_.gyro_range_deg_s * kDegToRad / 32768.0;
      pending_.imu.gyro_body_rad_s = {k * i16(d), k * i16(d + 2), k * i16(d + 4)};
      pending_.has_gyro = true;
      break;
    }
    case 0x53: {
      const double k = params_.angle_range_deg / 32768.0;
      pending_.angle_deg = {k * i16(d), k * i16(d + 2), k * i16(d + 4)};
      pending_.has_angle = true;
      break;
    }
    case 0x54:
      pending_.mag_uT = params_.mag_uT_per_lsb * Eigen::Vector3d(i16(d), i16(d + 2), i16(d + 4));
      pending_.has_mag = true;
      break;
    case 0x56:
      pending_.pressure_pa = i32(d);
      pending_.height_m = i32(d + 4) / 100.0;
      pending_.has_pressure = true;
      break;
    default:
      ++stats_.unknown_type;
  }
  last_type_ = type;
  if (pending_acc_ && type == cycle_end_) {
    pending_.imu.t_s = t_s;
    emit();
  }
}

void WitMotionDecoder::emit() {
  if (!pending_acc_) return;
  if (!pending_.has_gyro) pending_.imu.gyro_body_rad_s = Eigen::Vector3d::Constant(std::nan(""));
  ++stats_.samples;
  if (callback_) callback_(pending_);
  pending_ = WitSample();
  pending_acc_ = false;
}

void WitMotionDecoder::flush() { emit(); }

std::array<std::uint8_t, 11> encode_wit_packet(std::uint8_t type,
                                               std::array<std::int16_t, 4> data) {
  std::array<std::uint8_t, 11> p{};
  p[0] = kHeader;
  p[1] = type;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto u = static_cast<std::uint16_t>(data[i]);
    p[2 + 2 * i] = static_cast<std::uint8_t>(u & 0xFFu);
    p[3 + 2 * i] = static_cast<std::uint8_t>(u >> 8);
  }
  p[10] = checksum(p.data());
  return p;
}

std::vector<std::uint8_t> encode_wit_sample(const WitSample& s, const WitMotionParams& params) {
  std::vector<std::uint8_t> out;
  out.reserve(5 * 11);
  auto add = [&out](const std::array<std::uint8_t, 11>& p) {
    for (const std::uint8_t b : p) out.push_back(b);  // (insert() trips a GCC 12 false warning)
  };
  const double ka = 32768.0 / (params.acc_range_g * kG);
  const auto& a = s.imu.acc_body_m_s2;
  const auto temp = to_i16(s.temperature_c * 100.0);
  add(encode_wit_packet(0x51, {to_i16(a.x() * ka), to_i16(a.y() * ka), to_i16(a.z() * ka), temp}));
  if (s.has_gyro) {
    const double kw = 32768.0 / (params.gyro_range_deg_s * kDegToRad);
    const auto& w = s.imu.gyro_body_rad_s;
    add(encode_wit_packet(0x52,
                          {to_i16(w.x() * kw), to_i16(w.y() * kw), to_i16(w.z() * kw), temp}));
  }
  if (s.has_angle) {
    const double k = 32768.0 / params.angle_range_deg;
    add(encode_wit_packet(0x53, {to_i16(s.angle_deg.x() * k), to_i16(s.angle_deg.y() * k),
                                 to_i16(s.angle_deg.z() * k), 0}));
  }
  if (s.has_mag) {
    const double k = 1.0 / params.mag_uT_per_lsb;
    add(encode_wit_packet(0x54, {to_i16(s.mag_uT.x() * k), to_i16(s.mag_uT.y() * k),
                                 to_i16(s.mag_uT.z() * k), temp}));
  }
  if (s.has_pressure) {
    const auto p = static_cast<std::uint32_t>(to_i32(s.pressure_pa));
    const auto h = static_cast<std::uint32_t>(to_i32(s.height_m * 100.0));
    add(encode_wit_packet(
        0x56, {static_cast<std::int16_t>(p & 0xFFFFu), static_cast<std::int16_t>(p >> 16),
               static_cast<std::int16_t>(h & 0xFFFFu), static_cast<std::int16_t>(h >> 16)}));
  }
  return out;
}

WitMotionSerial::WitMotionSerial(const std::string& device, int baud,
                                 WitMotionDecoder::Callback callback, WitMotionParams params)
    : fd_(open_serial_raw(device, baud)), decoder_(std::move(callback), params) {}

WitMotionSerial::~WitMotionSerial() {
  if (fd_ >= 0) ::close(fd_);
}

bool WitMotionSerial::poll_once(int timeout_ms) {
  pollfd pfd{fd_, POLLIN, 0};
  const int r = ::poll(&pfd, 1, timeout_ms);
  if (r < 0) return errno == EINTR;
  if (r == 0) return true;
  if ((pfd.revents & POLLIN) == 0) return (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) == 0;
  std::array<std::uint8_t, 512> buf{};
  const ssize_t n = ::read(fd_, buf.data(), buf.size());
  if (n < 0) return errno == EAGAIN || errno == EINTR;
  if (n == 0) return false;
  const double t_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  decoder_.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)), t_s);
  return true;
}

void WitMotionSerial::run(const std::atomic<bool>& stop) {
  while (!stop.load() && poll_once(100)) {
  }
  decoder_.flush();
}

}  // namespace telltale::sensors
