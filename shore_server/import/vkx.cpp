#include "vkx.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::shore::import {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

std::uint64_t u64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
std::int32_t i32(const unsigned char* p) {
  const std::uint32_t u = static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
                          static_cast<std::uint32_t>(p[2]) << 16 |
                          static_cast<std::uint32_t>(p[3]) << 24;
  return static_cast<std::int32_t>(u);
}
double f32(const unsigned char* p) {
  const std::uint32_t u = static_cast<std::uint32_t>(i32(p));
  float f;
  std::memcpy(&f, &u, sizeof f);
  return static_cast<double>(f);
}

std::string hex(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v & 0xFFu);
  return buf;
}

}  // namespace

int vkx_payload_size(unsigned key) {
  switch (key) {
    case 0xFF: return 7;
    case 0xFE: return 2;
    case 0x01: return 32;
    case 0x02: return 44;
    case 0x03: return 20;
    case 0x04: return 13;
    case 0x05: return 17;
    case 0x06: return 18;
    case 0x07: return 12;
    case 0x08: return 13;
    case 0x0A: return 16;
    case 0x0B: return 16;
    case 0x0C: return 12;
    case 0x0E: return 16;
    case 0x0F: return 16;
    case 0x10: return 12;
    case 0x20: return 13;
    case 0x21: return 52;
    default: return -1;
  }
}

ParseResult parse_vkx(std::istream& in, const ImportOptions& options, ImportSink& sink) {
  ParseResult r;
  std::array<unsigned char, 64> buf{};
  std::uint64_t offset = 0;
  bool seen_header = false;
  ImportPoint last_pvo;  // the boat's velocity and heading for the apparent wind rows
  std::uint64_t last_pvo_ns = 0;
  auto partial = [&](const std::string& why) {
    r.status = r.points > 0 ? ParseStatus::kPartial : ParseStatus::kError;
    r.message = why;
    return r;
  };
  for (;;) {
    const int key = in.get();
    if (key == std::char_traits<char>::eof()) break;
    const int size = vkx_payload_size(static_cast<unsigned>(key));
    if (size < 0)
      return partial("unknown row key " + hex(static_cast<unsigned>(key)) + " at byte offset " +
                     std::to_string(offset) + ": the rest of the file cannot be framed");
    if (!seen_header && key != 0xFF)
      return partial("byte offset 0: a VKX file starts with a page header (0xFF), found " +
                     hex(static_cast<unsigned>(key)));
    in.read(reinterpret_cast<char*>(buf.data()), size);
    if (in.gcount() != size)
      return partial("row " + hex(static_cast<unsigned>(key)) + " at byte offset " +
                     std::to_string(offset) + " cut by the end of the file (" +
                     std::to_string(in.gcount()) + " of " + std::to_string(size) + " bytes)");
    const unsigned char* p = buf.data();
    switch (key) {
      case 0xFF:
        seen_header = true;
        break;
      case 0x02: {
        ImportPoint pt;
        const std::uint64_t ms = u64(p);
        if (ms == 0 || ms > 7'258'118'400'000ULL) {  // after 2200: not a time
          ++r.skipped;
          break;
        }
        pt.t_utc_ns = ms * 1'000'000ULL;
        const double lat = i32(p + 8) * 1e-7, lon = i32(p + 12) * 1e-7;
        if (std::fabs(lat) <= 90.0 && std::fabs(lon) <= 180.0 && !(lat == 0.0 && lon == 0.0)) {
          pt.lat_deg = lat;
          pt.lon_deg = lon;
        }
        const double sog = f32(p + 16);
        if (std::isfinite(sog) && sog >= 0.0 && sog < 100.0) pt.sog_m_s = sog;
        pt.cog_deg = fusion::wrap_360_deg(f32(p + 20) * kRadToDeg);
        const Euler e = euler_from_ned_quaternion(f32(p + 28), f32(p + 32), f32(p + 36), f32(p + 40));
        pt.heel_deg = e.heel_deg;
        pt.pitch_deg = e.pitch_deg;
        pt.heading_deg = e.heading_deg;
        last_pvo = pt;
        last_pvo_ns = pt.t_utc_ns;
        apply_offsets(options, pt);
        sink.point(pt);
        ++r.points;
        break;
      }
      case 0x0A: {
        // The Calypso sensor's apparent wind: made true with the boat's last position row (its
        // heading, SOG and COG), when that row is at most a second older.
        const std::uint64_t t = u64(p) * 1'000'000ULL;
        if (t >= last_pvo_ns && t - last_pvo_ns <= 1'000'000'000ULL && last_pvo_ns != 0) {
          const fusion::TrueWind w = fusion::true_wind(
              {fusion::WindRef::kApparent, f32(p + 8), f32(p + 12)}, last_pvo.heading_deg,
              last_pvo.sog_m_s, last_pvo.cog_deg, kNaN);
          if (std::isfinite(w.from_deg)) sink.wind({t, w.from_deg, w.speed_m_s, "vkx_apparent"});
        }
        break;
      }
      case 0x04: {
        static constexpr const char* kTimer[] = {"timer_reset", "timer_start", "timer_sync",
                                                 "race_start", "race_end"};
        const unsigned type = p[8];
        ImportEvent e{u64(p) * 1'000'000ULL, type < 5 ? kTimer[type] : "timer",
                      "timer_s=" + std::to_string(i32(p + 9))};
        sink.event(e);
        ++r.events;
        break;
      }
      case 0x05: {
        char where[64];
        std::snprintf(where, sizeof where, "lat=%.7f lon=%.7f", f32(p + 9), f32(p + 13));
        sink.event({u64(p) * 1'000'000ULL, p[8] == 0 ? "line_pin" : "line_boat", where});
        ++r.events;
        break;
      }
      default:
        break;  // known rows that carry nothing the store keeps (yet)
    }
    offset += 1 + static_cast<std::uint64_t>(size);
  }
  if (!seen_header) return partial("empty file");
  if (r.points == 0) {
    r.status = ParseStatus::kError;
    r.message = "no position rows (0x02) in " + std::to_string(offset) + " bytes";
  }
  return r;
}

}  // namespace telltale::shore::import
