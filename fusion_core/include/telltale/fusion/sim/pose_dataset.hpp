#pragma once
/// \file
/// Data sets drawn from the gait simulator for the PDR: labelled pose-feature windows (training
/// and held-out evaluation of the BP classifier) and calibration walks for the step-length model.
/// Person seeds pick the people: train on one range, evaluate on a disjoint one.

#include <cstdint>
#include <optional>
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

/// The personal step-length calibration an athlete does once: walk a straight, known `length_m`
/// (e.g. 100 m between two marks on a pontoon) at a normal pace with the phone in `pose`, then
/// step_scale = known length / PDR distance. `seed` draws that walk's noise and sensor biases
/// (another run than the evaluated one). Returns the factor for StepLengthParams::scale
/// (PdrParams::step_length).
[[nodiscard]] double personal_step_scale(const Person& person, std::uint64_t seed,
                                         PhonePose pose = PhonePose::kHandHeld,
                                         double length_m = 100.0);

/// One closed-loop PDR walk ("loop" scenario of the gait simulator) run through a Pdr.
struct LoopWalkResult {
  double distance_m = 0.0;               ///< true distance walked
  double end_error_m = 0.0;              ///< |estimated end - true end|
  double error_fraction = 0.0;           ///< end_error_m / distance_m
  double distance_error_fraction = 0.0;  ///< (PDR distance - true distance) / true distance
  double step_scale = 1.0;               ///< the personal factor from the calibration walk
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
/// Protocol: before the loop the person does one calibration walk of 100 m hand-held
/// (personal_step_scale, its own noise seed, never the evaluated walk), unless `calibrate` is
/// false (the population step-length model alone). With `pose`, the whole walk is in that pose
/// (the variant's switches, if any, are dropped).
[[nodiscard]] LoopWalkResult simulate_pdr_loop(std::uint64_t seed,
                                               LoopVariant variant = LoopVariant::kAsSimulated,
                                               bool calibrate = true,
                                               std::optional<PhonePose> pose = std::nullopt);

}  // namespace telltale::fusion::sim
