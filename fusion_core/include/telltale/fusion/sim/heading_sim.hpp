#pragma once
/// \file
/// Simulator of N heading sensors on a known heading profile, with faults. Pure and seeded:
/// the same scenario and seed give the same samples on every machine with the same libstdc++.
///
/// Every sample carries the truth (heading and turn rate) at its time, and the reading of each
/// sensor (NaN when the sensor has nothing at this tick). A sensor i reads every
/// `period_ticks` ticks (offset `offset_ticks`), sees the truth of `latency_s` ago, adds a
/// constant `bias_deg` and white noise `noise_deg`, and rounds to `resolution_deg` if > 0.
/// Readings are wrapped to [0, 360).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/heading_fusion.hpp"

namespace telltale::fusion::sim {

enum class HeadingProfile : std::uint8_t {
  kSmallChange,  ///< DP station keeping: a few degrees of slow yaw around 45 deg
  kLargeChange,  ///< course changes of 60..150 deg at up to 3 deg/s, through north
  kModel,        ///< a random walk of the paper's own model (F, G, Q): the model is exact
  kDinghy,       ///< upwind beats either side of north, 90-deg tacks in 4 s, wave yaw
};

struct HeadingSensorModel {
  double noise_deg = 0.1;
  double bias_deg = 0.0;
  double latency_s = 0.0;
  int period_ticks = 1;  ///< reads every period_ticks base ticks (rate = 1 / (period * dt))
  int offset_ticks = 0;
  double resolution_deg = 0.0;
};

enum class HeadingFaultKind : std::uint8_t {
  kFrozen,    ///< output stuck at its last value
  kDrift,     ///< error grows by magnitude deg/min
  kSpikes,    ///< with probability `probability` per reading, +-magnitude deg
  kSilent,    ///< no readings
  kBiasStep,  ///< a constant +magnitude deg
};

/// A fault of one sensor over [t_start_s, t_end_s); after t_end_s the sensor is healthy again.
struct HeadingFault {
  int sensor = 0;
  HeadingFaultKind kind = HeadingFaultKind::kFrozen;
  double t_start_s = 0.0;
  double t_end_s = 0.0;
  double magnitude = 0.0;
  double probability = 0.0;
};

struct HeadingScenario {
  std::string name;
  HeadingProfile profile = HeadingProfile::kDinghy;
  double duration_s = 120.0;
  double dt_s = 0.1;  ///< base tick
  std::vector<HeadingSensorModel> sensors;
  std::vector<HeadingFault> faults;
  /// The fusion settings that match these sensors (noise, latency, Q): what an installer sets.
  HeadingFusionParams fusion;
};

struct HeadingSimSample {
  double t_s = 0.0;
  double truth_heading_deg = 0.0;  ///< [0, 360)
  double truth_rate_deg_s = 0.0;
  std::vector<double> reading_deg;  ///< one per sensor, NaN = no reading at this tick
};

/// Named scenarios: "paper-small", "paper-large", "paper-model", "dinghy", "dinghy-frozen",
/// "dinghy-drift", "dinghy-spikes", "dinghy-silent", "dinghy-bias", "dinghy-two-fail".
[[nodiscard]] std::vector<std::string_view> heading_scenario_names();
[[nodiscard]] std::optional<HeadingScenario> heading_scenario(std::string_view name);

/// Runs the scenario. The kModel profile draws its truth from the seed as well.
[[nodiscard]] std::vector<HeadingSimSample> simulate_heading(const HeadingScenario& scenario,
                                                             std::uint64_t seed);

/// True while any fault of `sensor` is active at t_s.
[[nodiscard]] bool heading_fault_active(const HeadingScenario& scenario, int sensor, double t_s);

}  // namespace telltale::fusion::sim
