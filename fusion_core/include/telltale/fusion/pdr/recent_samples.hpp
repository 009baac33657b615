#pragma once
/// \file
/// PDR stage (phone pipeline): the last seconds of raw samples, and what the phone's step
/// detection, cadence and pose-switch detection ask of them: whether the phone stood still
/// between two moments, whether the acceleration repeats at a step interval, and a step's
/// waveform. Owned here so that those questions read one ring; the foot pipeline (FootPdr)
/// needs none.
///
/// Memory: fixed-size arrays (512 samples: 10 s at 50 Hz), no heap.

#include <array>
#include <cstddef>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// A stand: the phone still (|f| within acc_std_m_s2, rotating at less than gyro_rad_s rms)
/// for still_s. 0 s: no stand is ever seen.
struct StandLimits {
  double still_s = 0.6;
  double gyro_rad_s = 0.2;
  double acc_std_m_s2 = 0.15;
};

class RecentSamples {
 public:
  static constexpr std::size_t kCapacity = 512;
  static constexpr int kWave = 16;  ///< points per axis in a step waveform
  using Wave = Eigen::Matrix<double, 3 * kWave, 1>;
  explicit RecentSamples(StandLimits stand) : stand_(stand) {}
  /// Adds a sample (gyro bias removed; the gyro may be NaN); the oldest goes when full.
  void push(const ImuSample& s);
  /// Whether the phone was still for stand.still_s somewhere in [t0, t1]: a stand.
  [[nodiscard]] bool quiet_between(double t0_s, double t1_s) const;
  /// Whether the phone's acceleration repeats itself after `lag_s` (a step interval does).
  [[nodiscard]] bool walking_period(double lag_s) const;
  /// The acceleration over [t0, t1] at kWave points per axis (x points, then y, then z).
  [[nodiscard]] Wave step_wave(double t0_s, double t1_s) const;

 private:
  /// Index, from the oldest, of the first sample at or after t_s (size_ if none).
  [[nodiscard]] std::size_t first_at(double t_s) const;
  static constexpr double kNoGyroW2 = 1e6;  ///< far above any stand's
  StandLimits stand_;
  std::array<double, kCapacity> t_{};
  std::array<Eigen::Vector3d, kCapacity> f_{};
  std::array<double, kCapacity> w2_{};  ///< |w|^2 (kNoGyroW2 without a gyroscope)
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace telltale::fusion
