#pragma once
/// \file
/// Accuracy of attitude filters against ground truth: per-axis RMS/max errors on the simulator,
/// and the inclination metric of the BROAD dataset (angle between estimated and true up vectors).
/// Pure: recordings come in as vectors, the caller reads the files.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/sim/imu_errors.hpp"

namespace telltale::fusion {

/// Heel/pitch error statistics, degrees.
struct TiltErrorStats {
  double heel_rms_deg = 0.0;
  double pitch_rms_deg = 0.0;
  double heel_max_deg = 0.0;
  double pitch_max_deg = 0.0;
  std::size_t samples = 0;
  /// Merges another run (RMS over all samples, max of the maxima).
  void merge(const TiltErrorStats& other);
};

/// Runs filters side by side over one simulated run and scores every sample after the
/// scenario's warm-up; one result per filter name, in order. duration_s <= 0 picks the scenario's
/// default length; `errors` replaces the simulator's sensor profile (nullptr: the default).
/// An unknown scenario or filter name yields samples = 0.
[[nodiscard]] std::vector<TiltErrorStats> evaluate_on_scenario(
    const std::vector<std::string>& filter_names, std::string_view scenario_name,
    std::uint64_t seed, double rate_hz, double duration_s = 0.0,
    const sim::ImuErrorParams* errors = nullptr);

/// Angle (rad) between the up vectors of two heel/pitch pairs (heading does not matter).
[[nodiscard]] double inclination_error_rad(double heel_a_rad, double pitch_a_rad, double heel_b_rad,
                                           double pitch_b_rad);

/// A recording with heel/pitch truth (BROAD): rows not to be scored have scored = 0.
struct InclinationTrial {
  std::vector<ImuSample> imu;
  std::vector<double> heel_true_rad;
  std::vector<double> pitch_true_rad;
  std::vector<unsigned char> scored;
  /// The recording's sensor's full scales: a filter judged on it is told them (a reading within
  /// them is the motion, not a clipped one).
  SensorRanges sensor;
};

/// The trial as an IMU averaging to `rate_hz` (below the recording's rate) would have given it
/// (resample_spans: each sample the mean of the readings over the interval before it); its truth
/// and scored flag are the last reading's in that interval. At or above the recording's rate the
/// trial is returned as it is.
[[nodiscard]] InclinationTrial resample_trial(const InclinationTrial& trial, double rate_hz);

/// The index of the trial's first scored row (its size if none is scored).
[[nodiscard]] std::size_t first_scored(const InclinationTrial& trial);

/// The trial from row `from` on (empty past its end): a filter run on it from the first scored
/// row starts in motion, with nothing learnt at the rest a recording begins with.
[[nodiscard]] InclinationTrial trial_from(const InclinationTrial& trial, std::size_t from);

/// RMS inclination error (deg) of the filter over the scored rows of the trial.
[[nodiscard]] double inclination_rmse_deg(AttitudeFilter& filter, const InclinationTrial& trial);

}  // namespace telltale::fusion
