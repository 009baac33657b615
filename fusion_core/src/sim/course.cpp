// A boat sailing a windward-leeward race (see course.hpp).
#include "telltale/fusion/sim/course.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion::sim {
namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr double kUpwindTwa = 42.0;
constexpr double kBearAwayTwa = 120.0;
constexpr double kEarthR = 6371000.0;

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

const char* to_string(TruthKind k) {
  switch (k) {
    case TruthKind::kTack: return "tack";
    case TruthKind::kGybe: return "gybe";
    case TruthKind::kRounding: return "rounding";
    case TruthKind::kBearAway: return "bear_away";
    case TruthKind::kRoundUp: return "round_up";
    case TruthKind::kPenalty: return "penalty";
  }
  return "?";
}

CourseSim::CourseSim(std::uint64_t seed, CourseParams p)
    : p_(p), rng_(seed), drill_rng_(seed ^ 0x9E3779B97F4A7C15ULL) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  factor_ = 0.92 + 0.16 * u(rng_);
  phase1_ = 2.0 * M_PI * u(rng_);
  phase2_ = 2.0 * M_PI * u(rng_);
  side_ = u(rng_) < 0.5 ? 1 : -1;
  corridor_deg_ = 12.0 + 28.0 * u(rng_);
  {
    // Its downwind angle, from a stream of its own (the race's draws stay as they were): an
    // asymmetric-spinnaker dinghy runs at 135-148 deg to the true wind by its crew and its
    // rig, so its gybes turn 64-90 deg. (A 60 deg gybe for every boat sat on the detector's
    // threshold and tested nothing but its rounding.)
    std::mt19937_64 boat_rng(seed ^ 0xD1B54A32D192ED03ULL);
    downwind_twa_deg_ = 135.0 + 13.0 * u(boat_rng);
  }
  // Start line: across the wind, 60 m to windward of the leeward mark, boats spread along it.
  const double along = (u(rng_) - 0.5) * 120.0;
  const double up = p_.wind_from_deg * kDeg;
  x_m_ = 60.0 * std::sin(up) + along * std::cos(up);
  y_m_ = 60.0 * std::cos(up) - along * std::sin(up);
  wind_from_deg_ = p_.wind_from_deg;
  heading_deg_ = wrap_360_deg(wind_from_deg_ + side_ * -kUpwindTwa);
  speed_m_s_ = polar(p_.wind_m_s, kUpwindTwa) * factor_;
  tws_ = p_.wind_m_s;
  if (p_.drills) {
    // Some seeds bear away on a beat, some do a 720, most both.
    if (u(drill_rng_) < 0.8) bear_at_s_ = 60.0 + 240.0 * u(drill_rng_);
    if (u(drill_rng_) < 0.8) penalty_at_s_ = 300.0 + 400.0 * u(drill_rng_);
    spin_dir_ = u(drill_rng_) < 0.5 ? 1 : -1;
  }
}

void CourseSim::begin(TruthKind kind) {
  if (open_.active && t_s_ - open_.start_s < 8.0) {
    // A turn that runs into the next (a tack on the layline, then the mark): one manoeuvre,
    // named after the later (a rounding).
    open_.kind = kind;
    return;
  }
  if (open_.active) track_turn(0.0, 0.0, 0.0);  // interrupted later on: log what it was
  if (!log_.empty() && t_s_ - log_.back().end_s < 1.5 && kind == TruthKind::kRounding) {
    // A tack or gybe finished less than 1.5 s before the mark: no steady course between them
    // that GNSS could show (a course takes a second of fixes to read) or a coach would see, so
    // one turn, named after the later, as above.
    const TruthManoeuvre prev = log_.back();
    log_.pop_back();
    open_ = Open{};
    open_.active = true;
    open_.kind = kind;
    open_.start_s = prev.start_s;
    open_.turned = prev.turn_deg;
    open_.cross_s = prev.t_s;
    open_.crossed = prev.crossed;
    open_.prev_rel = diff_180_deg(heading_deg_, wind_from_deg_);
    open_.path.emplace_back(prev.start_s, 0.0);
    return;
  }
  open_ = Open{};
  open_.active = true;
  open_.kind = kind;
  open_.start_s = t_s_;
  open_.prev_rel = diff_180_deg(heading_deg_, wind_from_deg_);
  open_.path.emplace_back(t_s_, 0.0);
}

/// Follows the open manoeuvre: `turn` degrees this step; closed once the heading is on its new
/// target (`err` within 0.5 deg), or forced by begin().
void CourseSim::track_turn(double turn, double dt, double err) {
  if (!open_.active) return;
  open_.turned += turn;
  open_.path.emplace_back(t_s_, open_.turned);
  const double rel = diff_180_deg(heading_deg_, wind_from_deg_);
  if (open_.cross_s < 0 && (open_.prev_rel < 0) != (rel < 0) && std::abs(turn) > 0.0) {
    const bool through_eye = std::abs(rel) < 90.0;
    if (open_.kind == TruthKind::kTack || open_.kind == TruthKind::kGybe ||
        open_.kind == TruthKind::kRounding) {
      open_.cross_s = t_s_ - dt * 0.5;
      open_.crossed = through_eye ? 1 : 2;
    }
  }
  open_.prev_rel = rel;
  if (std::abs(err) > 0.5 || spin_left_deg_ > 0.0) return;
  TruthManoeuvre m;
  m.kind = open_.kind;
  m.turn_deg = open_.turned;
  m.start_s = open_.start_s;
  m.end_s = t_s_;
  m.wind_from_deg = wind_from_deg_;
  m.t_s = open_.cross_s;
  m.crossed = open_.crossed;
  if (m.t_s < 0) {  // half the turn done
    for (const auto& [t, a] : open_.path)
      if (std::abs(a) >= 0.5 * std::abs(open_.turned)) {
        m.t_s = t;
        break;
      }
  }
  if (std::abs(m.turn_deg) > 5.0) log_.push_back(m);
  open_.active = false;
}

void CourseSim::step(double dt) {
  t_s_ += dt;
  // Shifts: the sum of a 5-min and a 13-min oscillation (what a coach sees on a sea breeze).
  wind_from_deg_ = p_.wind_from_deg + 5.0 * std::sin(2 * M_PI * t_s_ / 300.0 + phase1_) +
                   3.0 * std::sin(2 * M_PI * t_s_ / 780.0 + phase2_);
  std::normal_distribution<double> n(0.0, 1.0);
  gust_ += (-gust_ / 20.0) * dt + 0.25 * std::sqrt(dt) * n(rng_);  // OU, ~0.8 m/s, 20 s
  const double tws = std::max(1.0, p_.wind_m_s + gust_);
  tws_ = tws;

  const double wx = upwind_ ? p_.leg_m * std::sin(p_.wind_from_deg * kDeg) : 0.0;
  const double wy = upwind_ ? p_.leg_m * std::cos(p_.wind_from_deg * kDeg) : 0.0;
  const double dx = wx - x_m_, dy = wy - y_m_;
  const double to_mark = wrap_360_deg(std::atan2(dx, dy) / kDeg);
  const bool drilling = bear_left_s_ > 0.0 || spin_left_deg_ > 0.0;
  if (std::hypot(dx, dy) < 15.0 && !drilling) {
    // Rounding: up to the other mark on the side that points at it.
    upwind_ = !upwind_;
    manoeuvre_s_ = 0.0;
    begin(TruthKind::kRounding);
  }
  // Drills: only away from the marks and from other manoeuvres.
  const bool clear = manoeuvre_s_ > 25.0 && drill_quiet_s_ > 25.0 && !drilling &&
                     std::hypot(dx, dy) > 150.0;
  if (clear && upwind_ && t_s_ >= bear_at_s_) {
    bear_at_s_ = 1e18;
    bear_left_s_ = 40.0;
    begin(TruthKind::kBearAway);
  } else if (clear && t_s_ >= penalty_at_s_) {
    penalty_at_s_ = 1e18;
    spin_left_deg_ = 720.0;
    begin(TruthKind::kPenalty);
  }
  if (bear_left_s_ > 0.0) {
    bear_left_s_ -= dt;
    if (bear_left_s_ <= 0.0) {
      begin(TruthKind::kRoundUp);
      drill_quiet_s_ = 0.0;
    }
  }
  const double twa = upwind_ ? (bear_left_s_ > 0.0 ? kBearAwayTwa : kUpwindTwa) : downwind_twa_deg_;
  // Tack / gybe: the mark's bearing from the leg's axis (upwind: into the wind, downwind: with
  // it) drifts away from the side the boat sails on; once it is `corridor_deg_` on the other
  // side (never beyond the layline), turn. Each boat has its own corridor: some play the middle,
  // some go to the laylines.
  const double axis = upwind_ ? wind_from_deg_ : wrap_360_deg(wind_from_deg_ + 180.0);
  const double rel = diff_180_deg(to_mark, axis);
  const double offset = upwind_ ? -side_ * twa : side_ * (180.0 - twa);
  const double limit = std::min(corridor_deg_, std::abs(offset) - 2.0);
  if (manoeuvre_s_ > 20.0 && rel * offset < 0.0 && std::abs(rel) >= limit && !drilling &&
      drill_quiet_s_ > 20.0) {
    side_ = -side_;
    manoeuvre_s_ = 0.0;
    ++tacks_;
    begin(upwind_ ? TruthKind::kTack : TruthKind::kGybe);
  }
  manoeuvre_s_ += dt;
  drill_quiet_s_ += dt;
  const double target = wrap_360_deg(wind_from_deg_ - side_ * twa);
  // Helm: turn towards the target at up to 20 deg/s (a tack takes ~4 s); in a 720, round and
  // round at that rate.
  const double err = diff_180_deg(target, heading_deg_);
  double turn = std::clamp(err, -20.0 * dt, 20.0 * dt);
  if (spin_left_deg_ > 0.0) {
    turn = spin_dir_ * std::min(20.0 * dt, spin_left_deg_);
    spin_left_deg_ -= std::abs(turn);
    if (spin_left_deg_ <= 1e-9) {
      spin_left_deg_ = 0.0;
      drill_quiet_s_ = 0.0;
    }
  }
  heading_deg_ = wrap_360_deg(heading_deg_ + turn);
  const double v_target = polar(tws, diff_180_deg(heading_deg_, wind_from_deg_)) * factor_;
  // A tack or gybe costs speed: halved at the turn, back with an 8 s time constant.
  const double loss = manoeuvre_s_ < 4.0 || spin_left_deg_ > 0.0 ? 0.5 : 1.0;
  speed_m_s_ += (v_target * loss - speed_m_s_) * std::min(1.0, dt / 8.0);
  x_m_ += speed_m_s_ * std::sin(heading_deg_ * kDeg) * dt;
  y_m_ += speed_m_s_ * std::cos(heading_deg_ * kDeg) * dt;
  // Heel (no random draws): to leeward, more upwind, with the wind; 1 s lag.
  const double r = diff_180_deg(heading_deg_, wind_from_deg_);
  const double a = std::abs(r);
  const double h = (a < 30.0 ? 14.0 * a / 30.0 : a < 90.0 ? 14.0 : 14.0 - 9.0 * (a - 90.0) / 90.0) *
                   std::min(tws / p_.wind_m_s, 1.5);
  const double heel_target = (r < 0 ? -1.0 : 1.0) * h;
  heel_deg_ += (heel_target - heel_deg_) * std::min(1.0, dt / 1.0);
  track_turn(turn, dt, diff_180_deg(target, heading_deg_));
}

CourseState CourseSim::at(double t_s) {
  while (t_s_ + 0.05 <= t_s) step(0.05);
  CourseState r;
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
  r.t_s = t_s;
  r.lat_deg = p_.origin_lat_deg + ny / kEarthR / kDeg;
  r.lon_deg = p_.origin_lon_deg + ex / (kEarthR * std::cos(p_.origin_lat_deg * kDeg)) / kDeg;
  r.sog_m_s = std::max(0.0, speed_m_s_ + 0.05 * n(rng_));
  r.cog_deg = wrap_360_deg(heading_deg_ + 1.0 * n(rng_));
  r.heading_deg = heading_deg_;
  r.wind_from_deg = wind_from_deg_;
  r.wind_m_s = tws_;
  r.heel_deg = heel_deg_;
  r.east_m = x_m_;
  r.north_m = y_m_;
  r.upwind = upwind_;
  return r;
}

}  // namespace telltale::fusion::sim
