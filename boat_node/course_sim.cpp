// A boat sailing a windward-leeward race (see course_sim.hpp).
#include "course_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace telltale::boat {
namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kUpwindTwa = 42.0;
constexpr double kDownwindTwa = 150.0;
constexpr double kEarthR = 6371000.0;

double wrap360(double a) {
  a = std::fmod(a, 360.0);
  return a < 0 ? a + 360.0 : a;
}
/// a - b wrapped to (-180, 180].
double diff180(double a, double b) {
  double d = std::fmod(a - b + 540.0, 360.0) - 180.0;
  return d == -180.0 ? 180.0 : d;
}
/// Boat speed from true wind speed and angle: a dinghy-like polar (no planing), m/s.
double polar(double tws, double twa_deg) {
  const double a = std::abs(twa_deg);
  const double base = std::min(tws, 8.0);
  if (a < 30.0) return 0.2 * base;
  if (a < 60.0) return base * (0.50 + 0.12 * (a - 42.0) / 18.0);
  if (a < 120.0) return base * 0.72;
  return base * (0.72 - 0.1 * (a - 120.0) / 60.0);
}
}  // namespace

CourseSim::CourseSim(std::uint64_t seed, CourseSimParams p) : p_(p), rng_(seed) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  factor_ = 0.92 + 0.16 * u(rng_);
  phase1_ = 2.0 * M_PI * u(rng_);
  phase2_ = 2.0 * M_PI * u(rng_);
  side_ = u(rng_) < 0.5 ? 1 : -1;
  corridor_deg_ = 12.0 + 28.0 * u(rng_);
  // Start line: across the wind, 60 m to windward of the leeward mark, boats spread along it.
  const double along = (u(rng_) - 0.5) * 120.0;
  const double up = p_.wind_from_deg * kDeg;
  x_m_ = 60.0 * std::sin(up) + along * std::cos(up);
  y_m_ = 60.0 * std::cos(up) - along * std::sin(up);
  wind_from_deg_ = p_.wind_from_deg;
  heading_deg_ = wrap360(wind_from_deg_ + side_ * -kUpwindTwa);
  speed_m_s_ = polar(p_.wind_m_s, kUpwindTwa) * factor_;
}

void CourseSim::step(double dt) {
  t_s_ += dt;
  // Shifts: the sum of a 5-min and a 13-min oscillation (what a coach sees on a sea breeze).
  wind_from_deg_ = p_.wind_from_deg + 5.0 * std::sin(2 * M_PI * t_s_ / 300.0 + phase1_) +
                   3.0 * std::sin(2 * M_PI * t_s_ / 780.0 + phase2_);
  std::normal_distribution<double> n(0.0, 1.0);
  gust_ += (-gust_ / 20.0) * dt + 0.25 * std::sqrt(dt) * n(rng_);  // OU, ~0.8 m/s, 20 s
  const double tws = std::max(1.0, p_.wind_m_s + gust_);

  const double wx = upwind_ ? p_.leg_m * std::sin(p_.wind_from_deg * kDeg) : 0.0;
  const double wy = upwind_ ? p_.leg_m * std::cos(p_.wind_from_deg * kDeg) : 0.0;
  const double dx = wx - x_m_, dy = wy - y_m_;
  const double to_mark = wrap360(std::atan2(dx, dy) / kDeg);
  if (std::hypot(dx, dy) < 15.0) {
    // Rounding: up to the other mark on the side that points at it.
    upwind_ = !upwind_;
    manoeuvre_s_ = 0.0;
  }
  const double twa = upwind_ ? kUpwindTwa : kDownwindTwa;
  // Tack / gybe: the mark's bearing from the leg's axis (upwind: into the wind, downwind: with
  // it) drifts away from the side the boat sails on; once it is `corridor_deg_` on the other
  // side (never beyond the layline), turn. Each boat has its own corridor: some play the middle,
  // some go to the laylines.
  const double axis = upwind_ ? wind_from_deg_ : wrap360(wind_from_deg_ + 180.0);
  const double rel = diff180(to_mark, axis);
  const double offset = upwind_ ? -side_ * twa : side_ * (180.0 - twa);
  const double limit = std::min(corridor_deg_, std::abs(offset) - 2.0);
  if (manoeuvre_s_ > 20.0 && rel * offset < 0.0 && std::abs(rel) >= limit) {
    side_ = -side_;
    manoeuvre_s_ = 0.0;
    ++tacks_;
  }
  manoeuvre_s_ += dt;
  const double target = wrap360(wind_from_deg_ - side_ * twa);
  // Helm: turn towards the target at up to 20 deg/s (a tack takes ~4 s).
  const double err = diff180(target, heading_deg_);
  const double turn = std::clamp(err, -20.0 * dt, 20.0 * dt);
  heading_deg_ = wrap360(heading_deg_ + turn);
  const double v_target = polar(tws, diff180(heading_deg_, wind_from_deg_)) * factor_;
  // A tack or gybe costs speed: halved at the turn, back with an 8 s time constant.
  const double loss = manoeuvre_s_ < 4.0 ? 0.5 : 1.0;
  speed_m_s_ += (v_target * loss - speed_m_s_) * std::min(1.0, dt / 8.0);
  x_m_ += speed_m_s_ * std::sin(heading_deg_ * kDeg) * dt;
  y_m_ += speed_m_s_ * std::cos(heading_deg_ * kDeg) * dt;
}

sensors::GnssReading CourseSim::at(double t_s, std::uint64_t utc_ns) {
  while (t_s_ + 0.05 <= t_s) step(0.05);
  sensors::GnssReading r;
  std::normal_distribution<double> n(0.0, 1.0);
  // A consumer receiver: position error ~1 m that wanders slowly (Gauss-Markov, 30 s: the
  // atmosphere and the satellite geometry change over tens of seconds, so fix-to-fix noise is
  // centimetres), Doppler speed noise 0.05 m/s.
  const double dt = std::max(0.0, t_s - last_fix_s_);
  last_fix_s_ = t_s;
  const double a = std::exp(-dt / 30.0), b = std::sqrt(1.0 - a * a);
  err_e_m_ = a * err_e_m_ + b * n(rng_);
  err_n_m_ = a * err_n_m_ + b * n(rng_);
  const double ex = x_m_ + err_e_m_, ny = y_m_ + err_n_m_;
  r.lat_deg = p_.origin_lat_deg + ny / kEarthR / kDeg;
  r.lon_deg = p_.origin_lon_deg + ex / (kEarthR * std::cos(p_.origin_lat_deg * kDeg)) / kDeg;
  r.sog_m_s = std::max(0.0, speed_m_s_ + 0.05 * n(rng_));
  r.cog_deg = wrap360(heading_deg_ + 1.0 * n(rng_));
  r.fix = sensors::GnssFixKind::k3D;
  r.satellites = 12;
  r.hdop = 0.8;
  r.time_of_day_s = std::numeric_limits<double>::quiet_NaN();
  r.utc_ns = utc_ns;
  return r;
}

}  // namespace telltale::boat
