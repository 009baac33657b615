#include "record.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "gpx.hpp"
#include "nmea_log.hpp"
#include "telltale/fusion/angles.hpp"
#include "vakaros_csv.hpp"
#include "vkx.hpp"
#include "vtk.hpp"

namespace telltale::shore::import {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

/// Exactly `n` digits at `s[pos]`.
std::optional<int> digits(std::string_view s, std::size_t pos, std::size_t n) {
  if (pos + n > s.size()) return std::nullopt;
  int v = 0;
  for (std::size_t i = pos; i < pos + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return std::nullopt;
    v = v * 10 + (s[i] - '0');
  }
  return v;
}

}  // namespace

const char* format_name(Format f) {
  switch (f) {
    case Format::kVakarosCsv:
      return "vakaros_csv";
    case Format::kVkx:
      return "vkx";
    case Format::kVtk:
      return "vtk";
    case Format::kNmea:
      return "nmea";
    case Format::kGpx:
      return "gpx";
  }
  return "?";
}

std::optional<Format> parse_format(std::string_view name) {
  for (Format f : {Format::kVakarosCsv, Format::kVkx, Format::kVtk, Format::kNmea, Format::kGpx})
    if (name == format_name(f)) return f;
  return std::nullopt;
}

ParseResult parse_log(Format format, std::istream& in, const ImportOptions& options,
                      ImportSink& sink) {
  switch (format) {
    case Format::kVakarosCsv:
      return parse_vakaros_csv(in, options, sink);
    case Format::kVkx:
      return parse_vkx(in, options, sink);
    case Format::kVtk:
      return parse_vtk(in, options, sink);
    case Format::kNmea:
      return parse_nmea_log(in, options, sink);
    case Format::kGpx:
      return parse_gpx(in, options, sink);
  }
  return {ParseStatus::kError, "unknown format", 0, 0, 0};
}

std::optional<std::int64_t> parse_utc_offset(std::string_view s) {
  s = trim(s);
  if (s == "Z" || s == "UTC" || s == "GMT") return 0;
  if (s.size() < 3 || (s[0] != '+' && s[0] != '-')) return std::nullopt;
  const int sign = s[0] == '-' ? -1 : 1;
  const auto hh = digits(s, 1, 2);
  if (!hh) return std::nullopt;
  int mm = 0;
  if (s.size() == 3) {
  } else if (s.size() == 5) {
    const auto m = digits(s, 3, 2);
    if (!m) return std::nullopt;
    mm = *m;
  } else if (s.size() == 6 && s[3] == ':') {
    const auto m = digits(s, 4, 2);
    if (!m) return std::nullopt;
    mm = *m;
  } else {
    return std::nullopt;
  }
  if (*hh > 14 || mm > 59) return std::nullopt;
  return sign * (static_cast<std::int64_t>(*hh) * 3600 + mm * 60);
}

std::optional<std::int64_t> days_from_civil(int y, int m, int d) {
  if (y < 1970 || y > 2200 || m < 1 || m > 12 || d < 1) return std::nullopt;
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  if (d > kDays[m - 1] + (m == 2 && leap ? 1 : 0)) return std::nullopt;
  // Howard Hinnant's days_from_civil algorithm (public domain description).
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = y / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

std::optional<std::uint64_t> parse_iso_time(std::string_view s,
                                            std::optional<std::int64_t> default_offset_s,
                                            bool* had_zone) {
  s = trim(s);
  const auto y = digits(s, 0, 4), mo = digits(s, 5, 2), d = digits(s, 8, 2);
  const auto h = digits(s, 11, 2), mi = digits(s, 14, 2), se = digits(s, 17, 2);
  if (!y || !mo || !d || !h || !mi || !se || s[4] != '-' || s[7] != '-' ||
      (s[10] != 'T' && s[10] != ' ') || s[13] != ':' || s[16] != ':')
    return std::nullopt;
  if (*h > 23 || *mi > 59 || *se > 60) return std::nullopt;
  const auto days = days_from_civil(*y, *mo, *d);
  if (!days) return std::nullopt;
  std::size_t pos = 19;
  std::int64_t frac_ns = 0;
  if (pos < s.size() && s[pos] == '.') {
    ++pos;
    std::int64_t scale = 100000000;
    const std::size_t start = pos;
    while (pos < s.size() && s[pos] >= '0' && s[pos] <= '9') {
      if (scale > 0) frac_ns += (s[pos] - '0') * scale;
      scale /= 10;
      ++pos;
    }
    if (pos == start) return std::nullopt;
  }
  std::optional<std::int64_t> offset;
  if (pos < s.size()) {
    offset = parse_utc_offset(s.substr(pos));
    if (!offset) return std::nullopt;
    if (had_zone) *had_zone = true;
  } else {
    if (had_zone) *had_zone = false;
    offset = default_offset_s;
    if (!offset) return std::nullopt;
  }
  const std::int64_t t_s =
      *days * 86400 + *h * 3600 + *mi * 60 + *se - *offset;
  if (t_s <= 0) return std::nullopt;
  return static_cast<std::uint64_t>(t_s) * 1'000'000'000ULL + static_cast<std::uint64_t>(frac_ns);
}

std::optional<double> parse_decimal(std::string_view s) {
  s = trim(s);
  if (s.empty()) return std::nullopt;
  // from_chars alone would take "nan" and "inf": only digits, sign, '.', exponent pass.
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c)) && c != '-' && c != '+' && c != '.' &&
        c != 'e' && c != 'E')
      return std::nullopt;
  if (s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

Euler euler_from_ned_quaternion(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!std::isfinite(n) || n < 1e-9) return {};
  w /= n;
  x /= n;
  y /= n;
  z /= n;
  // ZYX (yaw, pitch, roll) of the body FRD in NED: roll > 0 lowers the starboard side, pitch > 0
  // raises the bow, yaw is clockwise from north: the contract's heel, pitch and heading as they are.
  Euler e;
  e.heel_deg = std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)) * kRadToDeg;
  const double sp = std::clamp(2.0 * (w * y - z * x), -1.0, 1.0);
  e.pitch_deg = std::asin(sp) * kRadToDeg;
  e.heading_deg = fusion::wrap_360_deg(
      std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)) * kRadToDeg);
  return e;
}

void apply_offsets(const ImportOptions& options, ImportPoint& p) {
  p.heel_deg -= options.heel_offset_deg;
  p.pitch_deg -= options.pitch_offset_deg;
}

}  // namespace telltale::shore::import
