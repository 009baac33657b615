#include "nmea_wind.hpp"

#include <array>
#include <cmath>
#include <optional>

namespace telltale::sensors {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A speed in m/s from a value and its unit letter; NaN when either is missing or absurd.
double speed_m_s(std::string_view value, std::string_view unit) {
  double v;
  if (unit.size() != 1 || !parse_nmea_number(value, v) || v < 0.0) return kNaN;
  switch (unit[0]) {
    case 'K': v /= 3.6; break;
    case 'M': break;
    case 'N': v *= 1852.0 / 3600.0; break;
    case 'S': v *= 0.44704; break;
    default: return kNaN;
  }
  return v <= 100.0 ? v : kNaN;  // no wind on the water blows at 200 knots
}

std::optional<double> angle(std::string_view f) {
  double v;
  if (!parse_nmea_number(f, v) || v < 0.0 || v > 360.0) return std::nullopt;
  return v;
}

}  // namespace

NmeaWindResult parse_nmea_wind(std::string_view line, const NmeaParseOptions& options) {
  NmeaWindResult res;
  NmeaFrame frame;
  res.status = frame_nmea(line, options, frame);
  if (res.status != NmeaStatus::kOk) return res;
  const std::string_view type = frame.type;
  if (type != "MWV" && type != "MWD") {
    res.status = NmeaStatus::kUnsupported;
    return res;
  }
  res.status = NmeaStatus::kMalformed;
  std::array<std::string_view, 10> f{};
  const std::size_t n = split_nmea_fields(frame.fields, f);
  if (n > f.size()) return res;
  fusion::WindReading& w = res.reading;
  if (type == "MWV") {
    if (n < 5 || f[4] != "A") return res;
    const auto a = angle(f[0]);
    if (!a) return res;
    w.angle_deg = *a;
    w.speed_m_s = speed_m_s(f[2], f[3]);
    if (f[1] == "T") {
      w.ref = fusion::WindRef::kTrueOffBow;
    } else if (f[1] == "R" && std::isfinite(w.speed_m_s)) {
      w.ref = fusion::WindRef::kApparent;
    } else {
      return res;
    }
  } else {
    if (n < 8) return res;
    const auto t = angle(f[0]);
    const auto m = angle(f[2]);
    if (t && f[1] == "T") {
      w.ref = fusion::WindRef::kTrueDirection;
      w.angle_deg = *t;
    } else if (m && f[3] == "M") {
      w.ref = fusion::WindRef::kMagneticDirection;
      w.angle_deg = *m;
    } else {
      return res;
    }
    w.speed_m_s = speed_m_s(f[6], f[7]);
    if (!std::isfinite(w.speed_m_s)) w.speed_m_s = speed_m_s(f[4], f[5]);
  }
  res.status = NmeaStatus::kOk;
  return res;
}

}  // namespace telltale::sensors
