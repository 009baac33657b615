// NMEA 0183 GNSS sentences and the epoch assembler (see nmea_gnss.hpp).
#include "nmea_gnss.hpp"

#include <cmath>
#include <limits>

namespace telltale::sensors {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kKnotToMs = 1852.0 / 3600.0;
constexpr double kKmhToMs = 1.0 / 3.6;

/// "hhmmss" or "hhmmss.sss" -> seconds since midnight; empty -> NaN (ok).
bool parse_time(std::string_view f, double& out) {
  if (f.empty()) {
    out = kNaN;
    return true;
  }
  if (f.size() < 6 || (f.size() > 6 && f[6] != '.')) return false;
  double v = 0.0;
  if (!parse_nmea_number(f, v)) return false;
  const int hh = static_cast<int>(v / 10000.0);
  const int mm = static_cast<int>(v / 100.0) - hh * 100;
  const double ss = v - hh * 10000.0 - mm * 100.0;
  if (hh > 23 || mm > 59 || ss >= 61.0) return false;  // 60.x: a leap second
  out = hh * 3600.0 + mm * 60.0 + ss;
  return true;
}

/// "ddmm.mmmm" + N/S or "dddmm.mmmm" + E/W -> signed degrees; both empty -> NaN (ok).
bool parse_coordinate(std::string_view value, std::string_view dir, double max_deg, char plus,
                      char minus, double& out) {
  if (value.empty() && dir.empty()) {
    out = kNaN;
    return true;
  }
  if (dir.size() != 1 || (dir[0] != plus && dir[0] != minus)) return false;
  const std::size_t dot = value.find('.');
  const std::size_t int_digits = dot == std::string_view::npos ? value.size() : dot;
  if (int_digits < 3) return false;  // at least d + mm
  double v = 0.0;
  if (!parse_nmea_number(value, v)) return false;
  const double deg = std::floor(v / 100.0);
  const double min = v - deg * 100.0;
  if (min >= 60.0) return false;
  out = deg + min / 60.0;
  if (out > max_deg) return false;
  if (dir[0] == minus) out = -out;
  return true;
}

/// Optional non-negative number: empty -> NaN (ok).
bool parse_optional(std::string_view f, double& out) {
  if (f.empty()) {
    out = kNaN;
    return true;
  }
  return parse_nmea_number(f, out);
}

bool parse_count(std::string_view f, int& out) {
  if (f.empty()) {
    out = -1;
    return true;
  }
  double v = 0.0;
  if (!parse_nmea_number(f, v) || v != std::floor(v) || v > 255) return false;
  out = static_cast<int>(v);
  return true;
}

bool parse_angle_360(std::string_view f, double& out) {
  if (!parse_optional(f, out)) return false;
  if (std::isnan(out)) return true;
  if (out > 360.0) return false;
  if (out == 360.0) out = 0.0;
  return true;
}

/// FAA mode indicator (NMEA 2.3+): A autonomous, D differential, F float RTK, R RTK, P precise
/// are fixes; N (none), E (estimated, dead reckoning), M (manual), S (simulator) are not
/// measured positions. An empty field (receivers before 2.3) says nothing.
bool apply_mode(char m, NmeaGnss& g) {
  switch (m) {
    case 'A':
      return true;
    case 'D':
    case 'F':
    case 'R':
    case 'P':
      g.differential = true;
      return true;
    case 'N':
    case 'E':
    case 'M':
    case 'S':
      g.no_fix = true;
      return true;
    default:
      return false;
  }
}

bool parse_mode_field(std::string_view f, NmeaGnss& g) {
  if (f.empty()) return true;
  if (f.size() != 1) return false;
  return apply_mode(f[0], g);
}

/// GNS: one mode character per constellation (GPS, GLONASS, Galileo, BeiDou, ...): a fix when
/// any constellation has one, differential when any is differential.
bool parse_gns_mode(std::string_view f, NmeaGnss& g) {
  if (f.empty() || f.size() > 8) return false;
  bool any_fix = false;
  bool any_diff = false;
  for (char c : f) {
    NmeaGnss one;
    if (!apply_mode(c, one)) return false;
    any_fix = any_fix || !one.no_fix;
    any_diff = any_diff || one.differential;
  }
  g.no_fix = !any_fix;
  g.differential = any_diff;
  return true;
}

bool parse_date(std::string_view f, int& out) {
  if (f.empty()) {
    out = -1;
    return true;
  }
  if (f.size() != 6) return false;
  for (char c : f)
    if (c < '0' || c > '9') return false;
  const int dd = (f[0] - '0') * 10 + (f[1] - '0');
  const int mo = (f[2] - '0') * 10 + (f[3] - '0');
  if (dd < 1 || dd > 31 || mo < 1 || mo > 12) return false;
  out = dd * 10000 + mo * 100 + (f[4] - '0') * 10 + (f[5] - '0');
  return true;
}

}  // namespace

NmeaGnssResult parse_nmea_gnss(std::string_view line, const NmeaParseOptions& options) {
  NmeaGnssResult res;
  NmeaFrame frame;
  res.status = frame_nmea(line, options, frame);
  if (res.status != NmeaStatus::kOk) return res;
  NmeaGnss& g = res.gnss;
  g.talker = frame.talker;
  g.time_of_day_s = kNaN;
  g.lat_deg = g.lon_deg = g.sog_m_s = g.cog_deg = g.hdop = kNaN;
  std::array<std::string_view, 20> f{};
  const std::size_t n = split_nmea_fields(frame.fields, f);
  res.status = NmeaStatus::kMalformed;
  if (frame.type == "RMC") {
    // time, status, lat, N/S, lon, E/W, sog kn, cog, date, var, var E/W [, mode [, nav status]]
    if (n < 11 || n > 13) return res;
    g.sentence = GnssSentence::kRmc;
    if (!parse_time(f[0], g.time_of_day_s)) return res;
    if (f[1] == "V") {
      g.no_fix = true;
    } else if (f[1] != "A") {
      return res;
    }
    if (!parse_coordinate(f[2], f[3], 90.0, 'N', 'S', g.lat_deg)) return res;
    if (!parse_coordinate(f[4], f[5], 180.0, 'E', 'W', g.lon_deg)) return res;
    if (!parse_optional(f[6], g.sog_m_s)) return res;
    g.sog_m_s *= kKnotToMs;
    if (!parse_angle_360(f[7], g.cog_deg)) return res;
    if (!parse_date(f[8], g.date_ddmmyy)) return res;
    if (n >= 12 && !parse_mode_field(f[11], g)) return res;
  } else if (frame.type == "GGA") {
    // time, lat, N/S, lon, E/W, quality, satellites, hdop, alt, M, separation, M, age, station
    if (n != 14) return res;
    g.sentence = GnssSentence::kGga;
    if (!parse_time(f[0], g.time_of_day_s)) return res;
    if (!parse_coordinate(f[1], f[2], 90.0, 'N', 'S', g.lat_deg)) return res;
    if (!parse_coordinate(f[3], f[4], 180.0, 'E', 'W', g.lon_deg)) return res;
    if (f[5].size() != 1 || f[5][0] < '0' || f[5][0] > '8') return res;
    g.gga_quality = f[5][0] - '0';
    // 0 invalid, 6 estimated (dead reckoning), 7 manual, 8 simulator: not measured fixes.
    g.no_fix = g.gga_quality == 0 || g.gga_quality >= 6;
    g.differential = g.gga_quality == 2 || g.gga_quality == 4 || g.gga_quality == 5;
    if (!parse_count(f[6], g.satellites)) return res;
    if (!parse_optional(f[7], g.hdop)) return res;
  } else if (frame.type == "VTG") {
    // cog T, "T", cog M, "M", sog kn, "N", sog km/h, "K" [, mode]
    if (n < 8 || n > 9) return res;
    if ((!f[1].empty() && f[1] != "T") || (!f[5].empty() && f[5] != "N") ||
        (!f[7].empty() && f[7] != "K"))
      return res;
    g.sentence = GnssSentence::kVtg;
    if (!parse_angle_360(f[0], g.cog_deg)) return res;
    double kn = kNaN, kmh = kNaN;
    if (!parse_optional(f[4], kn) || !parse_optional(f[6], kmh)) return res;
    g.sog_m_s = std::isfinite(kn) ? kn * kKnotToMs : kmh * kKmhToMs;
    if (n == 9 && !parse_mode_field(f[8], g)) return res;
  } else if (frame.type == "GSA") {
    // selection mode, fix mode, 12 satellite ids, PDOP, HDOP, VDOP [, system id]
    if (n < 17 || n > 18) return res;
    g.sentence = GnssSentence::kGsa;
    if (f[1].size() != 1 || f[1][0] < '1' || f[1][0] > '3') return res;
    g.gsa_mode = f[1][0] - '0';
    g.no_fix = g.gsa_mode == 1;
    if (!parse_optional(f[15], g.hdop)) return res;
  } else if (frame.type == "GNS") {
    // time, lat, N/S, lon, E/W, mode chars, satellites, hdop, alt, separation, age, station
    // [, nav status]
    if (n < 12 || n > 13) return res;
    g.sentence = GnssSentence::kGns;
    if (!parse_time(f[0], g.time_of_day_s)) return res;
    if (!parse_coordinate(f[1], f[2], 90.0, 'N', 'S', g.lat_deg)) return res;
    if (!parse_coordinate(f[3], f[4], 180.0, 'E', 'W', g.lon_deg)) return res;
    if (!parse_gns_mode(f[5], g)) return res;
    if (!parse_count(f[6], g.satellites)) return res;
    if (!parse_optional(f[7], g.hdop)) return res;
  } else {
    res.status = NmeaStatus::kUnsupported;
    return res;
  }
  // A position must come whole: a latitude without a longitude is a broken sentence.
  if (std::isnan(g.lat_deg) != std::isnan(g.lon_deg)) return res;
  res.status = NmeaStatus::kOk;
  return res;
}

// ------------------------------------------------------------------------- epochs

void GnssEpochAssembler::reset() {
  open_ = false;
  tod_s_ = kNaN;
  date_ = -1;
  lat_ = lon_ = sog_ = cog_ = hdop_ = kNaN;
  have_pos_ = have_rmc_speed_ = no_fix_ = differential_ = false;
  quality_ = gsa_mode_ = sats_ = -1;
}

GnssReading GnssEpochAssembler::merged() const {
  GnssReading r;
  r.time_of_day_s = tod_s_;
  r.date_ddmmyy = date_;
  r.satellites = sats_ > 0 ? sats_ : 0;
  r.hdop = hdop_;
  if (!have_pos_ || no_fix_) {
    // Any sentence of the epoch saying "no fix" wins: a receiver that contradicts itself is
    // not trusted with a position.
    r.fix = GnssFixKind::kNone;
    r.lat_deg = r.lon_deg = r.sog_m_s = r.cog_deg = kNaN;
    return r;
  }
  r.lat_deg = lat_;
  r.lon_deg = lon_;
  r.sog_m_s = sog_;
  r.cog_deg = cog_;
  r.fix = differential_ ? GnssFixKind::kDgnss
                        : (gsa_mode_ == 2 ? GnssFixKind::k2D : GnssFixKind::k3D);
  return r;
}

std::optional<GnssReading> GnssEpochAssembler::add(const NmeaGnss& g, double t_s) {
  std::optional<GnssReading> done;
  if (open_ && std::isfinite(g.time_of_day_s) && std::isfinite(tod_s_) &&
      std::abs(g.time_of_day_s - tod_s_) > 1e-3) {
    done = merged();
    reset();
  }
  if (!open_) reset();
  open_ = true;
  last_t_s_ = t_s;
  if (std::isfinite(g.time_of_day_s)) tod_s_ = g.time_of_day_s;
  if (g.date_ddmmyy >= 0) date_ = g.date_ddmmyy;
  no_fix_ = no_fix_ || g.no_fix;
  differential_ = differential_ || g.differential;
  if (std::isfinite(g.lat_deg)) {
    lat_ = g.lat_deg;
    lon_ = g.lon_deg;
    have_pos_ = true;
  }
  // Speed and course: RMC's pair first (one sentence, one instant), VTG's when no RMC came.
  if (g.sentence == GnssSentence::kRmc || (g.sentence == GnssSentence::kVtg && !have_rmc_speed_)) {
    if (std::isfinite(g.sog_m_s)) sog_ = g.sog_m_s;
    if (std::isfinite(g.cog_deg)) cog_ = g.cog_deg;
    have_rmc_speed_ = have_rmc_speed_ || g.sentence == GnssSentence::kRmc;
  }
  if (g.gga_quality >= 0) quality_ = g.gga_quality;
  if (g.gsa_mode >= 0) gsa_mode_ = g.gsa_mode;
  if (g.satellites >= 0) sats_ = g.satellites;
  if (std::isfinite(g.hdop)) hdop_ = g.hdop;
  return done;
}

std::optional<GnssReading> GnssEpochAssembler::flush_if_quiet(double t_s) {
  if (!open_ || t_s - last_t_s_ < quiet_s_) return std::nullopt;
  GnssReading r = merged();
  reset();
  return r;
}

}  // namespace telltale::sensors
