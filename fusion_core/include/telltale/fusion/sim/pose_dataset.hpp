#pragma once
/// \file
/// Data sets drawn from the gait simulator for the PDR: labelled pose-feature windows (training
/// and held-out evaluation of the BP classifier) and calibration walks for the step-length model.
/// Person seeds pick the people: train on one range, evaluate on a disjoint one.

#include <cstdint>
#include <vector>

#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::fusion::sim {

struct PoseWindowSet {
  std::vector<PoseFeatures> features;
  std::vector<PhonePose> labels;
};

/// For each person seed in [first, first + people) and each pose: a walk of 20 s slow, 20 s
/// normal, 20 s fast, phone at 50 Hz; `windows_per_pose` feature windows (2 s) spread over it.
/// Seed 003 used 29 people and 460 windows per pose; 23 people x 20 windows gives the same 460.
[[nodiscard]] PoseWindowSet simulate_pose_windows(std::uint64_t first, int people,
                                                  int windows_per_pose = 20);

/// For each person seed and each gait of {slow walk, walk, fast walk}: a 40 s straight walk with
/// the phone in `pose`, run through a Pdr with `net`; returns the step frequencies it measured at
/// each step and the true distance (what a user calibrating on a known track would have).
[[nodiscard]] std::vector<CalibrationWalk> simulate_calibration_walks(std::uint64_t first,
                                                                      int people, PhonePose pose,
                                                                      const PoseNetwork& net);

}  // namespace telltale::fusion::sim

namespace telltale::fusion::sim {

/// One closed-loop PDR walk ("loop" scenario of the gait simulator) run through a Pdr.
struct LoopWalkResult {
  double distance_m = 0.0;      ///< true distance walked
  double end_error_m = 0.0;     ///< |estimated end - true end|
  double error_fraction = 0.0;  ///< end_error_m / distance_m
  std::size_t steps_true = 0;
  std::size_t steps_counted = 0;
  unsigned switches_true = 0;  ///< pose changes in the schedule
  unsigned switches_detected = 0;
};
enum class LoopVariant {
  kAsSimulated,   ///< pose switches, full sensor error model
  kSinglePose,    ///< the same walk in its first pose only (no switch)
  kIdealSensors,  ///< pose switches, no biases, no hard iron, no misalignment (noise only)
};
/// Person and loop drawn from `seed` (people seeds 2001+ are not in the training range 1..23).
[[nodiscard]] LoopWalkResult simulate_pdr_loop(std::uint64_t seed,
                                               LoopVariant variant = LoopVariant::kAsSimulated);

}  // namespace telltale::fusion::sim
