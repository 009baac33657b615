#pragma once
/// \file
/// Runs a heading fusion method over a simulated scenario and scores it against the truth:
/// shared by the tests, `fusion_cli heading-eval` and the benchmark, so all three measure the
/// same thing.

#include <cstdint>
#include <vector>

#include "telltale/fusion/heading_fusion.hpp"
#include "telltale/fusion/sim/heading_sim.hpp"

namespace telltale::fusion::sim {

/// What happened to one fault of the scenario.
struct HeadingFaultOutcome {
  int sensor = 0;
  double harm_t_s = 0.0;      ///< first time the sensor's error exceeded 1 deg (or it went silent)
  double isolation_s = -1.0;  ///< from harm_t_s until the fusion stopped fusing it; -1 = never
  double readmit_s = -1.0;    ///< from the fault's end until it was fused again; -1 = never
  double readmit_jump_deg = 0.0;  ///< change of the fused error at re-admission
};

struct HeadingRunResult {
  double rms_deg = 0.0;      ///< RMS of the wrapped heading error after the settling time
  double max_err_deg = 0.0;  ///< largest |error| after the settling time
  double mean_nees = 0.0;    ///< mean of e^T P^-1 e over [heading, rate] (NaN for "average")
  std::uint64_t model_mismatches = 0;
  std::uint64_t exclusions = 0;  ///< times any sensor was isolated (false alarms if no fault)
  std::vector<HeadingFaultOutcome> faults;
  std::vector<double> fused_deg;      ///< per sample
  std::vector<double> error_deg;      ///< per sample, wrapped
  std::vector<double> nees;           ///< per sample (NaN when undefined)
  std::vector<std::uint16_t> in_use;  ///< per sample, Diagnostics::sensors_in_use
};

/// Settling time excluded from the scores, s.
inline constexpr double kHeadingSettleS = 2.0;

/// Runs `params` (its sensor_count is set from the scenario) over `samples`.
[[nodiscard]] HeadingRunResult run_heading(const HeadingScenario& scenario,
                                           const std::vector<HeadingSimSample>& samples,
                                           HeadingFusionParams params);

}  // namespace telltale::fusion::sim
