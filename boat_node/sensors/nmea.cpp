// NMEA 0183: framing, heading sentences, line assembler, serial and UDP readers (see nmea.hpp).
#include "nmea.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "serial_port.hpp"
#include "telltale/fusion/angles.hpp"

namespace telltale::sensors {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

using fusion::wrap_360_deg;

/// Optional signed angle: empty -> NaN with ok; "x.x" + 'E'/'W' -> +x / -x.
bool parse_signed(std::string_view value, std::string_view dir, double& out) {
  if (value.empty() && dir.empty()) {
    out = kNaN;
    return true;
  }
  double v = 0.0;
  if (!parse_nmea_number(value, v) || v > 180.0) return false;
  if (dir == "E") {
    out = v;
  } else if (dir == "W") {
    out = -v;
  } else {
    return false;
  }
  return true;
}

bool parse_heading_field(std::string_view f, double& out) {
  if (!parse_nmea_number(f, out) || out > 360.0) return false;
  out = wrap_360_deg(out);
  return true;
}

}  // namespace

bool parse_nmea_number(std::string_view f, double& out) {
  if (f.empty() || f.size() > 16) return false;
  int dots = 0;
  int digits = 0;
  for (char c : f) {
    if (c == '.') {
      ++dots;
    } else if (c >= '0' && c <= '9') {
      ++digits;
    } else {
      return false;
    }
  }
  if (dots > 1 || digits == 0) return false;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), out);
  return r.ec == std::errc() && r.ptr == f.data() + f.size() && std::isfinite(out);
}

NmeaStatus frame_nmea(std::string_view line, const NmeaParseOptions& options, NmeaFrame& out) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  if (line.size() > kNmeaMaxLine) return NmeaStatus::kTooLong;
  if (line.size() < 6 || line[0] != '$') return NmeaStatus::kNotNmea;
  for (std::size_t i = 1; i < 6; ++i) {
    const char c = line[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))) return NmeaStatus::kNotNmea;
  }
  // Checksum: XOR of everything between '$' and '*'.
  std::string_view body = line.substr(1);
  const std::size_t star = body.find('*');
  out.had_checksum = false;
  if (star != std::string_view::npos) {
    const std::string_view cs = body.substr(star + 1);
    body = body.substr(0, star);
    if (cs.size() != 2 || hex_value(cs[0]) < 0 || hex_value(cs[1]) < 0)
      return NmeaStatus::kBadChecksum;
    unsigned sum = 0;
    for (char c : body) sum ^= static_cast<unsigned char>(c);
    if (sum != static_cast<unsigned>(hex_value(cs[0]) * 16 + hex_value(cs[1])))
      return NmeaStatus::kBadChecksum;
    out.had_checksum = true;
  } else if (!options.accept_missing_checksum) {
    return NmeaStatus::kMissingChecksum;
  }
  for (char c : body) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e)
      return NmeaStatus::kMalformed;
  }
  out.talker = {body[0], body[1], '\0'};
  out.type = body.substr(2, 3);
  if (body.size() == 5) {
    out.fields = {};
  } else if (body[5] == ',') {
    out.fields = body.substr(6);
  } else {
    return NmeaStatus::kMalformed;
  }
  return NmeaStatus::kOk;
}

const char* nmea_status_name(NmeaStatus s) {
  switch (s) {
    case NmeaStatus::kOk:
      return "ok";
    case NmeaStatus::kNotNmea:
      return "not_nmea";
    case NmeaStatus::kUnsupported:
      return "unsupported";
    case NmeaStatus::kBadChecksum:
      return "bad_checksum";
    case NmeaStatus::kMissingChecksum:
      return "missing_checksum";
    case NmeaStatus::kMalformed:
      return "malformed";
    case NmeaStatus::kTooLong:
      return "too_long";
  }
  return "unknown";
}

NmeaParseResult parse_nmea_heading(std::string_view line, const NmeaParseOptions& options) {
  NmeaParseResult res;
  NmeaFrame frame;
  res.status = frame_nmea(line, options, frame);
  if (res.status != NmeaStatus::kOk) return res;
  NmeaHeading& h = res.heading;
  h.had_checksum = frame.had_checksum;
  h.talker = frame.talker;
  const std::string_view type = frame.type;
  if (type != "HDT" && type != "HDG" && type != "HDM") {
    res.status = NmeaStatus::kUnsupported;
    return res;
  }
  std::array<std::string_view, 5> f{};
  const std::size_t n = split_nmea_fields(frame.fields, f);
  res.status = NmeaStatus::kMalformed;
  h.deviation_deg = kNaN;
  h.variation_deg = kNaN;
  if (type == "HDT" || type == "HDM") {
    const bool is_true = type == "HDT";
    // "x.x,T" / "x.x,M"; the unit letter may be missing on some old talkers.
    if (n < 1 || n > 2 || (n == 2 && f[1] != (is_true ? "T" : "M") && !f[1].empty())) return res;
    double v = 0.0;
    if (!parse_heading_field(f[0], v)) return res;
    h.sentence = is_true ? NmeaSentence::kHdt : NmeaSentence::kHdm;
    h.true_deg = is_true ? v : kNaN;
    h.magnetic_deg = is_true ? kNaN : v;
  } else {
    // HDG: sensor heading, deviation, E/W, variation, E/W.
    if (n != 5) return res;
    double sensor = 0.0;
    if (!parse_heading_field(f[0], sensor)) return res;
    if (!parse_signed(f[1], f[2], h.deviation_deg)) return res;
    if (!parse_signed(f[3], f[4], h.variation_deg)) return res;
    h.sentence = NmeaSentence::kHdg;
    const double dev = std::isfinite(h.deviation_deg) ? h.deviation_deg : 0.0;
    h.magnetic_deg = wrap_360_deg(sensor + dev);
    h.true_deg =
        std::isfinite(h.variation_deg) ? wrap_360_deg(h.magnetic_deg + h.variation_deg) : kNaN;
  }
  res.status = NmeaStatus::kOk;
  return res;
}

// ------------------------------------------------------------------------- line assembler

void NmeaLineAssembler::finish(const LineCallback& on_line) {
  if (in_line_) {
    if (overflow_) {
      ++stats_.overlong;
    } else {
      ++stats_.lines;
      on_line(std::string_view(buf_.data(), len_));
    }
  }
  in_line_ = false;
  overflow_ = false;
  len_ = 0;
}

void NmeaLineAssembler::feed(const char* data, std::size_t size, const LineCallback& on_line) {
  for (std::size_t i = 0; i < size; ++i) {
    const char c = data[i];
    if (c == '$') {
      if (in_line_) ++stats_.truncated;  // a sentence cut short by the next one
      in_line_ = true;
      overflow_ = false;
      len_ = 0;
      buf_[len_++] = c;
    } else if (c == '\r' || c == '\n') {
      finish(on_line);
    } else if (!in_line_) {
      ++stats_.garbage_bytes;
    } else if (len_ < buf_.size()) {
      buf_[len_++] = c;
    } else {
      overflow_ = true;  // keep swallowing until the line ends; drop it whole
    }
  }
}

void NmeaLineAssembler::end_of_record(const LineCallback& on_line) { finish(on_line); }

// ------------------------------------------------------------------------- readers

NmeaStreamReader::NmeaStreamReader(NmeaParseOptions options) : options_(options) {
  if (::pipe2(stop_pipe_, O_CLOEXEC | O_NONBLOCK) != 0) {
    throw std::system_error(errno, std::generic_category(), "nmea: pipe");
  }
}

NmeaStreamReader::~NmeaStreamReader() {
  if (fd_ >= 0) ::close(fd_);
  for (int p : stop_pipe_) {
    if (p >= 0) ::close(p);
  }
}

void NmeaStreamReader::attach(int fd) { fd_ = fd; }

void NmeaStreamReader::stop() {
  stopped_.store(true);
  const char b = 1;
  [[maybe_unused]] const auto n = ::write(stop_pipe_[1], &b, 1);
}

NmeaReaderStats NmeaStreamReader::stats() const {
  NmeaReaderStats s;
  s.bytes = bytes_.load();
  s.accepted = accepted_.load();
  s.unsupported = unsupported_.load();
  s.bad_checksum = bad_checksum_.load();
  s.missing_checksum = missing_checksum_.load();
  s.malformed = malformed_.load();
  s.garbage_bytes = garbage_.load();
  return s;
}

void NmeaStreamReader::on_line(std::string_view line, NmeaClock::time_point t,
                               const NmeaLineHandler& handler) {
  switch (handler(line, t)) {
    case NmeaStatus::kOk:
      ++accepted_;
      break;
    case NmeaStatus::kUnsupported:
      ++unsupported_;
      break;
    case NmeaStatus::kBadChecksum:
      ++bad_checksum_;
      break;
    case NmeaStatus::kMissingChecksum:
      ++missing_checksum_;
      break;
    case NmeaStatus::kNotNmea:
    case NmeaStatus::kMalformed:
    case NmeaStatus::kTooLong:
      ++malformed_;
      break;
  }
}

void NmeaStreamReader::account_assembler() {
  const auto& a = assembler_.stats();
  garbage_.store(a.garbage_bytes);
  malformed_.fetch_add((a.overlong + a.truncated) - assembler_dropped_);
  assembler_dropped_ = a.overlong + a.truncated;
}

bool NmeaStreamReader::poll_once(int timeout_ms, const NmeaHeadingCallback& cb) {
  return poll_lines(timeout_ms, [this, &cb](std::string_view line, NmeaClock::time_point t) {
    const NmeaParseResult r = parse_nmea_heading(line, options_);
    if (r.status == NmeaStatus::kOk && cb) cb(r.heading, t);
    return r.status;
  });
}

bool NmeaStreamReader::poll_lines(int timeout_ms, const NmeaLineHandler& handler) {
  if (stopped_.load()) return false;
  pollfd fds[2] = {{fd_, POLLIN, 0}, {stop_pipe_[0], POLLIN, 0}};
  const int r = ::poll(fds, 2, timeout_ms);
  if (r < 0) return errno == EINTR && !stopped_.load();
  if (stopped_.load() || (fds[1].revents & POLLIN) != 0) return false;
  if (r == 0) return true;
  if ((fds[0].revents & POLLIN) != 0) {
    const bool ok = read_available(handler);
    account_assembler();
    return ok;
  }
  // POLLHUP / POLLERR without data: the device is gone.
  return (fds[0].revents & (POLLHUP | POLLERR | POLLNVAL)) == 0;
}

void NmeaStreamReader::run(const NmeaHeadingCallback& cb) {
  while (poll_once(200, cb)) {
  }
}

NmeaSerialReader::NmeaSerialReader(const std::string& device, int baud, NmeaParseOptions options)
    : NmeaStreamReader(options) {
  attach(open_serial_raw(device, baud));
}

bool NmeaSerialReader::read_available(const NmeaLineHandler& handler) {
  std::array<char, 512> buf{};
  const ssize_t n = ::read(fd(), buf.data(), buf.size());
  if (n < 0) return errno == EAGAIN || errno == EINTR;
  if (n == 0) return false;
  bytes_ += static_cast<std::uint64_t>(n);
  const auto t = NmeaClock::now();
  assembler_.feed(buf.data(), static_cast<std::size_t>(n),
                  [&](std::string_view line) { on_line(line, t, handler); });
  return true;
}

NmeaUdpReader::NmeaUdpReader(const std::string& address, std::uint16_t port,
                             NmeaParseOptions options)
    : NmeaStreamReader(options) {
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &sa.sin_addr) != 1) {
    throw std::invalid_argument("nmea: bad IPv4 address '" + address + "'");
  }
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "nmea: socket");
  attach(fd);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    throw std::system_error(errno, std::generic_category(),
                            "nmea: bind " + address + ":" + std::to_string(port));
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  port_ = ntohs(sa.sin_port);
}

bool NmeaUdpReader::read_available(const NmeaLineHandler& handler) {
  std::array<char, 2048> buf{};
  for (;;) {
    const ssize_t n = ::recv(fd(), buf.data(), buf.size(), 0);
    if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    bytes_ += static_cast<std::uint64_t>(n);
    const auto t = NmeaClock::now();
    const auto line = [&](std::string_view l) { on_line(l, t, handler); };
    assembler_.feed(buf.data(), static_cast<std::size_t>(n), line);
    assembler_.end_of_record(line);
  }
}

}  // namespace telltale::sensors
