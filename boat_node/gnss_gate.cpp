// The boat's GNSS gate (see gnss_gate.hpp).
#include "gnss_gate.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

namespace telltale::boat {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDay_ns = 86400e9;

/// Days since 1970-01-01 of a civil date (proleptic Gregorian).
std::int64_t days_from_civil(int y, int m, int d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int yoe = static_cast<int>(y - era * 400);
  const int doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}
}  // namespace

std::uint64_t gnss_utc_ns(double time_of_day_s, int date_ddmmyy, std::uint64_t near_utc_ns) {
  if (!std::isfinite(time_of_day_s)) return 0;
  const double tod_ns = time_of_day_s * 1e9;
  if (date_ddmmyy >= 0) {
    const int dd = date_ddmmyy / 10000, mo = date_ddmmyy / 100 % 100, yy = date_ddmmyy % 100;
    // Two-digit years: 1980 (the GPS epoch) .. 2079.
    const int year = yy < 80 ? 2000 + yy : 1900 + yy;
    const double day_ns = static_cast<double>(days_from_civil(year, mo, dd)) * kDay_ns;
    return static_cast<std::uint64_t>(day_ns + tod_ns);
  }
  const double near = static_cast<double>(near_utc_ns);
  const double day0 = std::floor(near / kDay_ns) * kDay_ns;
  double best = day0 + tod_ns;
  for (const double d : {day0 - kDay_ns, day0 + kDay_ns})
    if (std::abs(d + tod_ns - near) < std::abs(best - near)) best = d + tod_ns;
  return best > 0 ? static_cast<std::uint64_t>(best) : 0;
}

bool GnssGate::plausible(const Point& from, const Point& to) const {
  const double dt = std::abs(to.t_s - from.t_s);
  const double scatter = 6.0 * p_.noise_sigma_m *
                         std::max({1.0, std::isfinite(from.hdop) ? from.hdop : 1.0,
                                   std::isfinite(to.hdop) ? to.hdop : 1.0});
  return distance_m(from.lat_deg, from.lon_deg, to.lat_deg, to.lon_deg) <=
         p_.max_speed_m_s * dt + scatter;
}

std::optional<GnssFix> GnssGate::on_epoch(const sensors::GnssReading& r, double t_s,
                                          std::uint64_t boat_utc_ns) {
  ++stats_.epochs;
  GnssFix out;
  out.t_boat_ns = boat_utc_ns;
  out.gnss_utc_ns =
      r.utc_ns != 0 ? r.utc_ns : gnss_utc_ns(r.time_of_day_s, r.date_ddmmyy, boat_utc_ns);
  if (out.gnss_utc_ns != 0)
    clock_offset_s_ = (static_cast<double>(boat_utc_ns) - static_cast<double>(out.gnss_utc_ns)) / 1e9;
  out.satellites = std::clamp(r.satellites, 0, 255);
  out.hdop = r.hdop;
  const bool has_position = r.fix != sensors::GnssFixKind::kNone && std::isfinite(r.lat_deg) &&
                            std::isfinite(r.lon_deg) && std::abs(r.lat_deg) <= 90.0 &&
                            std::abs(r.lon_deg) <= 180.0;
  if (!has_position) {
    ++stats_.no_fix;
    out.fix = sensors::GnssFixKind::kNone;
    out.lat_deg = out.lon_deg = out.sog_m_s = out.cog_deg = kNaN;
    return out;
  }
  if (out.gnss_utc_ns != 0 && out.gnss_utc_ns == last_gnss_utc_ns_) {
    ++stats_.repeats;
    return std::nullopt;
  }
  const Point here{r.lat_deg, r.lon_deg, t_s, r.hdop};
  const bool speed_ok = !(r.sog_m_s > p_.max_speed_m_s);
  if (anchor_ && (!speed_ok || !plausible(*anchor_, here))) {
    ++stats_.jumps;
    // Rejected fixes that agree among themselves: a new track.
    if (n_pending_ > 0 && !plausible(pending_[n_pending_ - 1], here)) n_pending_ = 0;
    if (speed_ok && n_pending_ < static_cast<int>(std::size(pending_))) pending_[n_pending_++] = here;
    if (n_pending_ < p_.reanchor_after) return std::nullopt;
    ++stats_.reanchors;
  } else if (!speed_ok) {
    ++stats_.jumps;
    return std::nullopt;
  }
  n_pending_ = 0;
  anchor_ = here;
  last_gnss_utc_ns_ = out.gnss_utc_ns;
  ++stats_.fixes;
  out.fix = r.fix;
  out.lat_deg = r.lat_deg;
  out.lon_deg = r.lon_deg;
  out.sog_m_s = r.sog_m_s;
  out.cog_deg = (std::isfinite(r.sog_m_s) && r.sog_m_s >= p_.min_cog_speed_m_s) ? r.cog_deg : kNaN;
  return out;
}

}  // namespace telltale::boat
