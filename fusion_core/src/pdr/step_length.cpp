#include "telltale/fusion/pdr/step_length.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <numeric>

namespace telltale::fusion {

StepLengthModel::StepLengthModel() {
  // Generic walking coefficients (overridden by the shipped calibration in pose_bp.txt).
  for (auto& c : abc) c = Eigen::Vector3d(0.3, 0.4, -0.51);
}

double StepLengthModel::length_m(PhonePose pose, double height_m, double step_hz) const {
  const Eigen::Vector3d& c = abc[static_cast<std::size_t>(pose)];
  return std::max(0.0, c[0] * height_m + c[1] * step_hz + c[2]);
}

Eigen::Vector3d calibrate_step_length(const std::vector<CalibrationWalk>& walks,
                                      const Eigen::Vector3d& prior, double prior_weight) {
  // Each walk: a (N h) + b (sum f) + c N = D. Rows are divided by N so every walk weighs the
  // same whatever its length; ridge toward the prior keeps the unobservable combinations.
  Eigen::Matrix3d ata = prior_weight * Eigen::Matrix3d::Identity();
  Eigen::Vector3d atb = prior_weight * prior;
  for (const auto& w : walks) {
    if (w.step_hz.empty()) continue;
    const double n = static_cast<double>(w.step_hz.size());
    const double mean_f = std::accumulate(w.step_hz.begin(), w.step_hz.end(), 0.0) / n;
    const Eigen::Vector3d row(w.height_m, mean_f, 1.0);
    ata += row * row.transpose();
    atb += row * (w.distance_m / n);
  }
  return ata.ldlt().solve(atb);
}

}  // namespace telltale::fusion
