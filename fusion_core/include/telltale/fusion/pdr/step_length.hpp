#pragma once
/// \file
/// PDR stage: step length (seed 003 eq. (13)). Owns the per-pose model L = a h + b f + c, its
/// calibration from walks of known length, and the walker's own numbers (height, personal
/// factor), so that what a step is worth is decided in one place. No state: a step's length
/// depends only on the pose and the step frequency at that step.

#include <array>
#include <cstddef>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/phone_pose.hpp"

namespace telltale::fusion {

/// Seed 003 eq. (13): step length L = a*h + b*f_step + c per pose (h in m, f_step in Hz).
struct StepLengthModel {
  std::array<Eigen::Vector3d, kPoseCount> abc{};  ///< per pose: a (m/m), b (m/Hz), c (m)
  StepLengthModel();                              ///< generic walking coefficients
  [[nodiscard]] double length_m(PhonePose pose, double height_m, double step_hz) const;
};

/// A walk of known length used to calibrate the step-length model.
struct CalibrationWalk {
  double height_m = 1.75;
  std::vector<double> step_hz;  ///< estimated step frequency at each counted step
  double distance_m = 0.0;      ///< the known length of the walk
};
/// Least squares for (a, b, c): each walk says sum_i (a h + b f_i + c) = distance. With fewer
/// walks than unknowns (or walks that do not vary h and f) the solution stays as close as
/// possible to `prior` (ridge weight `prior_weight` per coefficient, relative to one walk).
[[nodiscard]] Eigen::Vector3d calibrate_step_length(const std::vector<CalibrationWalk>& walks,
                                                    const Eigen::Vector3d& prior,
                                                    double prior_weight = 1e-3);

struct StepLengthParams {
  double height_m = 1.75;  ///< walker's height, m
  /// Personal factor on the model's step length, per pose (1 = the population model). Set it from
  /// a calibration walk of known length: known distance / `output().distance_m` of that walk.
  std::array<double, kPoseCount> scale{1.0, 1.0, 1.0, 1.0};
};

/// The model applied to one walker.
class StepLength {
 public:
  using Params = StepLengthParams;
  StepLength(Params params, const StepLengthModel& model) : params_(params), model_(model) {}
  /// One step's length in `pose` at `step_hz`, m.
  [[nodiscard]] double step_m(PhonePose pose, double step_hz) const {
    return model_.length_m(pose, params_.height_m, step_hz) *
           params_.scale[static_cast<std::size_t>(pose)];
  }

 private:
  Params params_;
  StepLengthModel model_;
};

}  // namespace telltale::fusion
