#include "sim_source.hpp"

#include <cmath>

namespace telltale::boat {
namespace {
constexpr double kG = 9.80665;
constexpr double kDeg = M_PI / 180.0;
}  // namespace

SimSource::SimSource(std::uint64_t seed, double rate_hz) : rate_hz_(rate_hz), rng_(seed) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  mean_heel_deg_ = 8.0 + 14.0 * u(rng_);  // beating to windward: 8..22 deg to starboard
  roll_amp_deg_ = 2.0 + 4.0 * u(rng_);
  roll_period_s_ = 3.0 + 3.0 * u(rng_);
  roll_phase_ = 2.0 * M_PI * u(rng_);
  pitch_amp_deg_ = 2.0 + 3.0 * u(rng_);
  pitch_period_s_ = 2.0 + 2.0 * u(rng_);
  pitch_phase_ = 2.0 * M_PI * u(rng_);
}

fusion::ImuSample SimSource::next() {
  const double t = static_cast<double>(k_++) / rate_hz_;
  const double wr = 2.0 * M_PI / roll_period_s_;
  const double wp = 2.0 * M_PI / pitch_period_s_;
  // A slow gust cycle on top of the wave roll; a tack every 90 s flips the heel.
  const auto heel_at = [&](double tt) {
    const double gust = 4.0 * std::sin(2.0 * M_PI * tt / 23.0);
    const double tack = std::tanh(6.0 * std::sin(2.0 * M_PI * tt / 180.0));
    return (tack * (mean_heel_deg_ + gust) + roll_amp_deg_ * std::sin(wr * tt + roll_phase_)) *
           kDeg;
  };
  const auto pitch_at = [&](double tt) {
    return pitch_amp_deg_ * std::sin(wp * tt + pitch_phase_) * kDeg;
  };
  const double heel = heel_at(t);
  const double pitch = pitch_at(t);
  // Euler rates by central difference of the same smooth functions.
  const double h = 1e-3;
  const double heel_rate = (heel_at(t + h) - heel_at(t - h)) / (2 * h);
  const double pitch_rate = (pitch_at(t + h) - pitch_at(t - h)) / (2 * h);
  // Body rates from Euler rates, no yaw: p = dphi - dpsi sin(theta), q = dtheta cos(phi) + ...
  // with theta = -pitch (SPEC section 1: bow-up pitch is a negative rotation about +y).
  const double p = heel_rate;
  const double q = -pitch_rate * std::cos(heel);
  const double r = pitch_rate * std::sin(heel);
  fusion::ImuSample s;
  s.t_s = t;
  s.gyro_body_rad_s = {p + gyro_noise_(rng_), q + gyro_noise_(rng_), r + gyro_noise_(rng_)};
  s.acc_body_m_s2 = {kG * std::sin(pitch) + acc_noise_(rng_),
                     kG * std::cos(pitch) * std::sin(heel) + acc_noise_(rng_),
                     kG * std::cos(pitch) * std::cos(heel) + acc_noise_(rng_)};
  return s;
}

}  // namespace telltale::boat
