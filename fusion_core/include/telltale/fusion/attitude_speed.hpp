#pragma once
/// \file
/// The boat's speed as the attitude filter takes it (AttitudeFilter::set_speed): the last GNSS
/// speed over ground held between fixes (they come at 1-25 Hz, the IMU at 25-100 Hz), the rates
/// of change of the speed and of the course from two consecutive fixes, all forgotten once too
/// old (a receiver that lost its fix or stopped talking must not leave a stale speed in the
/// filter: unknown is safe, the filter then behaves as without GNSS).
///
///   GroundSpeedHold hold;
///   hold.on_fix(t_fix_s, sog_m_s, cog_deg);           // per fix (NaN speed: a no-fix)
///   filter.set_speed(hold.speed_m_s(t_s), hold.rate_m_s2(t_s), hold.cog_rate_rad_s(t_s));
///
/// A rate from two fixes is noisy (0.05 m/s of speed noise over 0.2 s is 0.35 m/s^2), but held
/// from one fix to the next its integral is the difference of the fixes: the attitude filter's
/// low-pass, which averages over seconds, sees that difference, not the noise of each rate.
///
/// Times: any clock, the same for fixes and queries, seconds, increasing.

#include <cmath>
#include <limits>

namespace telltale::fusion {

struct GroundSpeedParams {
  /// A fix older than this is forgotten: 2.5 s covers a 1 Hz receiver that missed one epoch.
  double max_age_s = 2.5;
  /// The rate of change needs two fixes at most this far apart (a longer gap says nothing about
  /// the acceleration in between).
  double max_rate_span_s = 2.5;
  /// Faster than this is not a boat's speed (the GNSS gate's limit): taken as unknown.
  double max_speed_m_s = 30.0;
  /// Below this the course over ground is the direction of the receiver's noise (0.05 m/s of
  /// velocity noise is 6 deg of course at 0.5 m/s): no course rate.
  double min_cog_speed_m_s = 0.5;
};

class GroundSpeedHold {
 public:
  explicit GroundSpeedHold(GroundSpeedParams p = {}) : p_(p) {}

  /// One fix at t_s with speed over ground sog_m_s (NaN or out of range: no speed, forgets) and
  /// course over ground cog_deg (true, clockwise from north; NaN: unknown).
  void on_fix(double t_s, double sog_m_s, double cog_deg) {
    if (!(sog_m_s >= 0.0 && sog_m_s <= p_.max_speed_m_s) || !std::isfinite(t_s)) {
      t_s_ = kNaN;
      speed_m_s_ = kNaN;
      rate_m_s2_ = 0.0;
      cog_rad_ = kNaN;
      cog_rate_rad_s_ = kNaN;
      return;
    }
    const double span = t_s - t_s_;  // NaN after a no-fix or at the start
    const bool paired = span > 0.0 && span <= p_.max_rate_span_s;
    rate_m_s2_ = paired ? (sog_m_s - speed_m_s_) / span : 0.0;
    const double cog = sog_m_s >= p_.min_cog_speed_m_s ? cog_deg * (M_PI / 180.0) : kNaN;
    // The turn between the two courses the short way round (NaN if either is unknown).
    cog_rate_rad_s_ = paired ? std::remainder(cog - cog_rad_, 2.0 * M_PI) / span : kNaN;
    t_s_ = t_s;
    speed_m_s_ = sog_m_s;
    cog_rad_ = cog;
  }
  /// The held speed at t_s, NaN when there is none or it is older than max_age_s.
  [[nodiscard]] double speed_m_s(double t_s) const {
    return t_s - t_s_ <= p_.max_age_s ? speed_m_s_ : kNaN;
  }
  /// Its rate of change over the last two fixes (0 when unknown), held like the speed.
  [[nodiscard]] double rate_m_s2(double t_s) const {
    return t_s - t_s_ <= p_.max_age_s ? rate_m_s2_ : 0.0;
  }
  /// The course's rate of change over the last two fixes, rad/s clockwise + (NaN when unknown),
  /// held like the speed.
  [[nodiscard]] double cog_rate_rad_s(double t_s) const {
    return t_s - t_s_ <= p_.max_age_s ? cog_rate_rad_s_ : kNaN;
  }

 private:
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  GroundSpeedParams p_;
  double t_s_ = kNaN;
  double speed_m_s_ = kNaN;
  double rate_m_s2_ = 0.0;
  double cog_rad_ = kNaN;
  double cog_rate_rad_s_ = kNaN;
};

}  // namespace telltale::fusion
