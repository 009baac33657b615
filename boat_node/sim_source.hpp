#pragma once
/// \file
/// A simulated IMU for the boat node: a dinghy rolling and pitching in a seaway, as smooth
/// functions of time, sampled in real time by the node's loop.

#include <cstdint>
#include <random>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::boat {

class SimSource {
 public:
  /// `seed` makes every boat of a demo fleet sail its own waves.
  SimSource(std::uint64_t seed, double rate_hz);
  /// The next sample (t_s counts from 0 at the node's start).
  fusion::ImuSample next();
  [[nodiscard]] double rate_hz() const { return rate_hz_; }

 private:
  double rate_hz_;
  std::uint64_t k_ = 0;
  double mean_heel_deg_;
  double roll_amp_deg_, roll_period_s_, roll_phase_;
  double pitch_amp_deg_, pitch_period_s_, pitch_phase_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> gyro_noise_{0.0, 0.003};
  std::normal_distribution<double> acc_noise_{0.0, 0.03};
};

}  // namespace telltale::boat
