#include "vtk.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "telltale/fusion/angles.hpp"

namespace telltale::shore::import {
namespace {

constexpr double kKnotToMS = 1852.0 / 3600.0;

/// A protobuf message in memory, read field by field.
class Wire {
 public:
  Wire(const unsigned char* p, std::size_t n) : p_(p), end_(p + n) {}
  bool done() const { return p_ == end_; }
  bool varint(std::uint64_t& v) {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (p_ == end_) return false;
      const unsigned char b = *p_++;
      v |= static_cast<std::uint64_t>(b & 0x7F) << shift;
      if (!(b & 0x80)) return true;
    }
    return false;
  }
  /// Next field: number and wire type; false when malformed.
  bool tag(std::uint32_t& field, unsigned& type) {
    std::uint64_t t;
    if (!varint(t) || (t >> 3) == 0 || (t >> 3) > 0x1FFFFFFF) return false;
    field = static_cast<std::uint32_t>(t >> 3);
    type = static_cast<unsigned>(t & 7);
    return true;
  }
  bool bytes(const unsigned char*& data, std::size_t& n) {
    std::uint64_t len;
    if (!varint(len) || len > static_cast<std::uint64_t>(end_ - p_)) return false;
    data = p_;
    n = static_cast<std::size_t>(len);
    p_ += n;
    return true;
  }
  bool skip(unsigned type) {
    std::uint64_t v;
    const unsigned char* d;
    std::size_t n;
    switch (type) {
      case 0: return varint(v);
      case 1: return advance(8);
      case 2: return bytes(d, n);
      case 5: return advance(4);
      default: return false;  // groups (3, 4) are not in this schema
    }
  }

 private:
  bool advance(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) < n) return false;
    p_ += n;
    return true;
  }
  const unsigned char* p_;
  const unsigned char* end_;
};

std::int64_t zigzag(std::uint64_t v) {
  return static_cast<std::int64_t>(v >> 1) ^ -static_cast<std::int64_t>(v & 1);
}

/// Reads the varint fields 1..max_field of a flat message into `values` (others skipped).
template <std::size_t N>
bool flat_varints(const unsigned char* data, std::size_t n, std::uint64_t (&values)[N],
                  bool (&present)[N]) {
  Wire w(data, n);
  while (!w.done()) {
    std::uint32_t field;
    unsigned type;
    if (!w.tag(field, type)) return false;
    if (type == 0 && field < N) {
      if (!w.varint(values[field])) return false;
      present[field] = true;
    } else if (!w.skip(type)) {
      return false;
    }
  }
  return true;
}

struct State {
  double declination_deg = kNaN;  ///< from the file
  std::uint64_t last_t_ns = 0;    ///< events carry no time: they take the last trackpoint's
};

/// Decodes one Record; false when it does not decode.
bool decode_record(const unsigned char* data, std::size_t n, const ImportOptions& options,
                   ImportSink& sink, State& st, ParseResult& r) {
  Wire rec(data, n);
  while (!rec.done()) {
    std::uint32_t field;
    unsigned type;
    if (!rec.tag(field, type)) return false;
    if (type != 2) {
      if (!rec.skip(type)) return false;
      continue;
    }
    const unsigned char* body;
    std::size_t len;
    if (!rec.bytes(body, len)) return false;
    std::uint64_t v[11] = {};
    bool has[11] = {};
    switch (field) {
      case 1: {  // Trackpoint
        if (!flat_varints(body, len, v, has)) return false;
        ImportPoint p;
        p.t_utc_ns = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(v[1])) * 100 +
                      static_cast<std::uint32_t>(v[2]) % 100) *
                     10'000'000ULL;
        if (p.t_utc_ns == 0) {
          ++r.skipped;
          break;
        }
        const double lat = static_cast<double>(zigzag(v[3])) * 1e-7;
        const double lon = static_cast<double>(zigzag(v[4])) * 1e-7;
        if (has[3] && has[4] && std::fabs(lat) <= 90.0 && std::fabs(lon) <= 180.0) {
          p.lat_deg = lat;
          p.lon_deg = lon;
        }
        if (has[5]) p.sog_m_s = static_cast<double>(static_cast<std::uint32_t>(v[5])) * 0.1 * kKnotToMS;
        if (has[6])
          p.cog_deg = fusion::wrap_360_deg(static_cast<double>(static_cast<std::uint32_t>(v[6])));
        if (has[7] || has[8] || has[9] || has[10]) {
          const Euler e = euler_from_ned_quaternion(
              static_cast<double>(zigzag(v[7])) * 1e-3, static_cast<double>(zigzag(v[8])) * 1e-3,
              static_cast<double>(zigzag(v[9])) * 1e-3, static_cast<double>(zigzag(v[10])) * 1e-3);
          // Same Euler sequence, z up: roll is heel as it is, pitch and yaw change sign.
          p.heel_deg = e.heel_deg;
          p.pitch_deg = -e.pitch_deg;
          const double decl =
              std::isfinite(st.declination_deg) ? st.declination_deg : options.declination_deg;
          p.heading_deg = fusion::wrap_360_deg(-e.heading_deg + decl);
        }
        apply_offsets(options, p);
        st.last_t_ns = p.t_utc_ns;
        sink.point(p);
        ++r.points;
        break;
      }
      case 2: {  // TimerEvent
        if (!flat_varints(body, len, v, has)) return false;
        static constexpr const char* kTimer[] = {"timer", "timer_start", "timer_stop",
                                                 "timer_expired", "timer_tick"};
        const std::uint64_t t = v[1] < 5 ? v[1] : 0;
        if (t == 4) break;  // a tick per second says nothing new
        sink.event({st.last_t_ns, kTimer[t],
                    "timer_s=" + std::to_string(static_cast<std::int32_t>(v[2]))});
        ++r.events;
        break;
      }
      case 16: {  // ButtonEvent
        if (!flat_varints(body, len, v, has)) return false;
        static constexpr const char* kButton[] = {"button", "button_rc", "line_pin",
                                                  "line_cleared", "button_max"};
        sink.event({st.last_t_ns, kButton[v[1] < 5 ? v[1] : 0], ""});
        ++r.events;
        break;
      }
      case 17: {  // HardwareDescription
        if (!flat_varints(body, len, v, has)) return false;
        sink.device("Velocitek model " + std::to_string(static_cast<std::int32_t>(v[1])) +
                    " serial " + std::to_string(static_cast<std::int32_t>(v[4])));
        break;
      }
      case 18: {  // MagneticDeclination
        if (!flat_varints(body, len, v, has)) return false;
        const double d = static_cast<double>(zigzag(v[1]));
        if (std::fabs(d) <= 180.0) st.declination_deg = d;
        break;
      }
      default:
        break;  // a record kind newer than the description: skipped
    }
  }
  return true;
}

}  // namespace

std::optional<std::int64_t> vtk_serial_number(std::string_view data) {
  const auto* p = reinterpret_cast<const unsigned char*>(data.data());
  std::size_t off = 0;
  while (off + 2 <= data.size()) {
    const std::size_t len = p[off] | static_cast<std::size_t>(p[off + 1]) << 8;
    if (off + 2 + len > data.size()) break;
    Wire rec(p + off + 2, len);
    std::uint32_t field;
    unsigned type;
    const unsigned char* body;
    std::size_t n;
    if (rec.tag(field, type) && field == 17 && type == 2 && rec.bytes(body, n)) {
      std::uint64_t v[5] = {};
      bool has[5] = {};
      if (flat_varints(body, n, v, has) && has[4] && static_cast<std::int32_t>(v[4]) > 0)
        return static_cast<std::int32_t>(v[4]);
      return std::nullopt;
    }
    off += 2 + len;
  }
  return std::nullopt;
}

bool looks_like_vtk(std::string_view data) {
  if (data.size() < 3) return false;
  const auto* p = reinterpret_cast<const unsigned char*>(data.data());
  const std::size_t len = p[0] | static_cast<std::size_t>(p[1]) << 8;
  if (len == 0 || len + 2 > data.size()) return false;
  Wire rec(p + 2, len);
  std::uint32_t field;
  unsigned type;
  if (!rec.tag(field, type) || type != 2 ||
      !(field == 1 || field == 2 || (field >= 16 && field <= 18)))
    return false;
  ImportOptions options;
  struct Null : ImportSink {
    void point(const ImportPoint&) override {}
    void event(const ImportEvent&) override {}
  } sink;
  State st;
  ParseResult r;
  return decode_record(p + 2, len, options, sink, st, r);
}

ParseResult parse_vtk(std::istream& in, const ImportOptions& options, ImportSink& sink) {
  ParseResult r;
  State st;
  std::vector<unsigned char> buf(65535);
  std::uint64_t offset = 0;
  auto stop = [&](const std::string& why) {
    r.status = r.points > 0 ? ParseStatus::kPartial : ParseStatus::kError;
    r.message = why;
    return r;
  };
  for (;;) {
    unsigned char head[2];
    in.read(reinterpret_cast<char*>(head), 2);
    if (in.gcount() == 0) break;
    if (in.gcount() == 1)
      return stop("byte offset " + std::to_string(offset) + ": record length cut by the end of the file");
    const std::size_t len = head[0] | static_cast<std::size_t>(head[1]) << 8;
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(len));
    if (static_cast<std::size_t>(in.gcount()) != len)
      return stop("record at byte offset " + std::to_string(offset) + " cut by the end of the file (" +
                  std::to_string(in.gcount()) + " of " + std::to_string(len) + " bytes)");
    if (!decode_record(buf.data(), len, options, sink, st, r))
      return stop("record at byte offset " + std::to_string(offset) +
                  " is not a protobuf Record: the file is corrupt or not VTK");
    offset += 2 + len;
  }
  if (r.points == 0) {
    r.status = ParseStatus::kError;
    r.message = "no trackpoints in " + std::to_string(offset) + " bytes";
  }
  return r;
}

}  // namespace telltale::shore::import
