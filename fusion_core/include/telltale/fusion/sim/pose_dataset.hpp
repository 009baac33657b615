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
