#pragma once
/// \file
/// The four ways of carrying a phone of seed 003, in the order of the pose classifier's outputs.

namespace telltale::fusion {

enum class PhonePose { kHandHeld = 0, kCall = 1, kPocket = 2, kArmSwing = 3 };
inline constexpr int kPoseCount = 4;

}  // namespace telltale::fusion
