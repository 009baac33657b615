#include "telltale/fusion/pdr/recent_samples.hpp"

#include <cmath>

namespace telltale::fusion {

void RecentSamples::push(const ImuSample& s) {
  if (size_ == kCapacity) {
    head_ = (head_ + 1) % kCapacity;
    --size_;
  }
  t_[(head_ + size_) % kCapacity] = s.t_s;
  f_[(head_ + size_) % kCapacity] = s.acc_body_m_s2;
  w2_[(head_ + size_) % kCapacity] =
      s.gyro_body_rad_s.allFinite() ? s.gyro_body_rad_s.squaredNorm() : kNoGyroW2;
  ++size_;
}

RecentSamples::Wave RecentSamples::step_wave(double t0, double t1) const {
  Wave w = Wave::Zero();
  if (size_ == 0) return w;
  // Index into the ring from the oldest: the last sample before t0 (the ring holds 10 s).
  std::size_t j = first_at(t0);
  j = j > 0 ? j - 1 : 0;
  for (int i = 0; i < kWave; ++i) {
    const double t = t0 + (t1 - t0) * (i + 0.5) / kWave;
    while (j + 1 < size_ && t_[(head_ + j + 1) % kCapacity] <= t) ++j;
    const Eigen::Vector3d& f = f_[(head_ + j) % kCapacity];
    for (int a = 0; a < 3; ++a) w[a * kWave + i] = f[a];
  }
  return w;
}

std::size_t RecentSamples::first_at(double t_s) const {
  // From the newest back: a step's worth of samples, not the whole ring.
  std::size_t i = size_;
  while (i > 0 && t_[(head_ + i - 1) % kCapacity] >= t_s) --i;
  return i;
}

bool RecentSamples::quiet_between(double t0_s, double t1_s) const {
  // A walker who stopped holds the phone still for a moment: |f| steady and little rotation
  // (|f| alone is steady in a slow arm swing, whose pendulum acceleration is mostly across
  // gravity). A walking trunk never is, for any stretch of a step. Without a gyroscope the
  // rotation is unknown and no stretch counts as still.
  const double window_s = stand_.still_s;
  if (!(window_s > 0.0)) return false;
  const double w2_limit = stand_.gyro_rad_s * stand_.gyro_rad_s;
  const double limit = stand_.acc_std_m_s2;
  const std::size_t first = first_at(t0_s);
  double sum = 0.0, sum2 = 0.0, sum_w2 = 0.0;
  std::size_t lo = first;
  for (std::size_t i = first; i < size_; ++i) {
    const std::size_t k = (head_ + i) % kCapacity;
    if (t_[k] > t1_s) break;
    const double m = f_[k].norm();
    sum += m;
    sum2 += m * m;
    sum_w2 += w2_[k];
    while (t_[(head_ + lo) % kCapacity] < t_[k] - window_s) {
      const std::size_t kl = (head_ + lo) % kCapacity;
      const double ml = f_[kl].norm();
      sum -= ml;
      sum2 -= ml * ml;
      sum_w2 -= w2_[kl];
      ++lo;
    }
    const auto n = static_cast<double>(i - lo + 1);
    if (t_[k] - t_[(head_ + lo) % kCapacity] >= window_s * 0.9 && n >= 5) {
      const double var = sum2 / n - (sum / n) * (sum / n);
      if (var < limit * limit && sum_w2 / n < w2_limit) return true;
    }
  }
  return false;
}

bool RecentSamples::walking_period(double lag_s) const {
  constexpr double kSpanS = 4.0;
  // Autocorrelation of |f| over the last few seconds at that lag: a step interval repeats the
  // step (r ~ 0.5-0.9 even in a pocket, where the stride is the waveform's period); half of one
  // puts a valley on a peak (r < 0).
  if (size_ < 8 || !(lag_s > 0.0)) return false;
  const double t_end = t_[(head_ + size_ - 1) % kCapacity];
  const std::size_t first = first_at(t_end - kSpanS);
  const std::size_t n = size_ - first;
  const double dt = (t_end - t_[(head_ + first) % kCapacity]) / static_cast<double>(n - 1);
  const auto lag = static_cast<std::size_t>(std::lround(lag_s / dt));
  if (!(dt > 0.0) || lag == 0 || 2 * lag >= n) return false;
  const auto mag = [&](std::size_t i) { return f_[(head_ + first + i) % kCapacity].norm(); };
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += mag(i);
  mean /= static_cast<double>(n);
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i + lag < n; ++i) num += (mag(i) - mean) * (mag(i + lag) - mean);
  for (std::size_t i = 0; i < n; ++i) den += (mag(i) - mean) * (mag(i) - mean);
  return den > 0.0 && num / den * static_cast<double>(n) / static_cast<double>(n - lag) > 0.3;
}

}  // namespace telltale::fusion
