// MEMS error model (datasheet figures in the header).
#include "telltale/fusion/sim/imu_errors.hpp"

#include <cmath>

namespace telltale::fusion::sim {
namespace {

Eigen::Matrix3d error_matrix(std::mt19937_64& rng, double scale_max, double misalign_max) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    m(i, i) += scale_max * u(rng);
    for (int j = 0; j < 3; ++j) {
      if (i != j) m(i, j) = misalign_max * u(rng);
    }
  }
  return m;
}

double quantise_saturate(double x, double lsb, double full_scale) {
  const double q = lsb > 0.0 ? lsb * std::round(x / lsb) : x;
  return std::min(full_scale, std::max(-full_scale, q));
}

}  // namespace

ImuErrorParams ImuErrorParams::uncalibrated() {
  ImuErrorParams p;
  p.acc_bias_max_m_s2 = 0.020 * kStandardGravity_m_s2;  // LA_TyOff +-20 mg
  p.acc_scale_max = 0.10;                 // LA_So 0.9..1.1 mg/digit
  p.acc_misalign_max_rad = 0.01;
  p.gyro_scale_max = 0.02;         // sensitivity change vs temperature +-2 % (Table 4)
  p.gyro_misalign_max_rad = 0.01;  // 1 % cross-axis, typical MEMS (no datasheet figure)
  return p;
}

ImuErrorParams ImuErrorParams::ideal() {
  ImuErrorParams p;
  p.gyro_bias_max_rad_s = p.gyro_bias_walk_rad_s_sqrt_s = p.gyro_noise_density_rad_s_sqrt_hz = 0;
  p.gyro_scale_max = p.gyro_misalign_max_rad = p.gyro_lsb_rad_s = 0;
  p.acc_bias_max_m_s2 = p.acc_bias_walk_m_s2_sqrt_s = p.acc_noise_density_m_s2_sqrt_hz = 0;
  p.acc_scale_max = p.acc_misalign_max_rad = p.acc_lsb_m_s2 = 0;
  p.gyro_full_scale_rad_s = p.acc_full_scale_m_s2 = 1e300;
  return p;
}

ImuErrorModel::ImuErrorModel(const ImuErrorParams& params, std::uint64_t seed)
    : p_(params), rng_(seed ^ 0x9E3779B97F4A7C15ull) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  gyro_m_ = error_matrix(rng_, p_.gyro_scale_max, p_.gyro_misalign_max_rad);
  acc_m_ = error_matrix(rng_, p_.acc_scale_max, p_.acc_misalign_max_rad);
  for (int i = 0; i < 3; ++i) gyro_bias_(i) = p_.gyro_bias_max_rad_s * u(rng_);
  for (int i = 0; i < 3; ++i) acc_bias_(i) = p_.acc_bias_max_m_s2 * u(rng_);
}

void ImuErrorModel::apply(double dt_s, double rate_hz, const Eigen::Vector3d& gyro_true,
                          const Eigen::Vector3d& acc_true, Eigen::Vector3d& gyro,
                          Eigen::Vector3d& acc) {
  const double sqrt_dt = std::sqrt(std::max(0.0, dt_s));
  const double white = std::sqrt(0.5 * rate_hz);
  for (int i = 0; i < 3; ++i) {
    gyro_bias_(i) += p_.gyro_bias_walk_rad_s_sqrt_s * sqrt_dt * normal_(rng_);
    acc_bias_(i) += p_.acc_bias_walk_m_s2_sqrt_s * sqrt_dt * normal_(rng_);
  }
  Eigen::Vector3d g = gyro_m_ * gyro_true + gyro_bias_;
  Eigen::Vector3d a = acc_m_ * acc_true + acc_bias_;
  for (int i = 0; i < 3; ++i) {
    g(i) += p_.gyro_noise_density_rad_s_sqrt_hz * white * normal_(rng_);
    a(i) += p_.acc_noise_density_m_s2_sqrt_hz * white * normal_(rng_);
    gyro(i) = quantise_saturate(g(i), p_.gyro_lsb_rad_s, p_.gyro_full_scale_rad_s);
    acc(i) = quantise_saturate(a(i), p_.acc_lsb_m_s2, p_.acc_full_scale_m_s2);
  }
}

}  // namespace telltale::fusion::sim
