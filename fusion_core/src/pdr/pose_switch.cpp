#include "telltale/fusion/pdr/pose_switch.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/pdr/walking_heading.hpp"

namespace telltale::fusion {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

}  // namespace

PoseSwitch::Event PoseSwitch::at_step(const Wave& w) {
  // Pose switch (seed 003): cross-correlation of this step's waveform with the same foot's
  // previous one. A turn also changes the waveform, so we add a condition of our own: the
  // gravity direction in the sensor frame must have moved (the phone was re-oriented).
  Eigen::Vector3d tilt(w.segment<kWave>(0).mean(), w.segment<kWave>(kWave).mean(),
                       w.segment<kWave>(2 * kWave).mean());
  tilt.normalize();
  const auto slot = static_cast<std::size_t>(wave_count_ % 2);
  Event event = Event::kNone;
  if (wave_count_ >= 2) {
    const Wave a = w.array() - w.mean();
    const Wave b = waves_[slot].array() - waves_[slot].mean();
    const double den = a.norm() * b.norm();
    const double r = den > 1e-9 ? a.dot(b) / den : 0.0;
    const double tilt_deg = std::acos(std::clamp(tilt.dot(tilts_[slot]), -1.0, 1.0)) * 180.0 / M_PI;
    const bool changed = (r < params_.correlation && tilt_deg > params_.tilt_deg) ||
                         tilt_deg > 2.0 * params_.tilt_deg;
    if (!switching_ && changed) {
      switching_ = true;
      settling_ = false;
      correlated_steps_ = 0;
      event = Event::kBegan;
    } else if (switching_) {
      correlated_steps_ =
          (r >= params_.correlation && tilt_deg < params_.tilt_deg) ? correlated_steps_ + 1 : 0;
      if (!settling_ && correlated_steps_ >= params_.exit_steps) {
        // The phone is steady again: wait for fresh classifications of the new pose.
        settling_ = true;
        settling_steps_ = 0;
        event = Event::kSettling;
      }
    }
  }
  waves_[slot] = w;
  tilts_[slot] = tilt;
  if (step_up_.norm() > 0.0) ups_[slot] = step_up_.normalized();
  last_slot_ = slot;
  ++wave_count_;
  return event;
}

void PoseSwitch::choose_stand_in(std::size_t back, double straight_deg) {
  // If the 3 steps before the switch were straight, their mean heading stands in for
  // the heading during the switch. The comparison spans two steps, so the switch may
  // have begun during the latest step: the 3 steps before the re-laid ones (at least
  // the latest) are the ones known to be clean.
  have_stand_in_ = false;
  const std::size_t skip = std::max<std::size_t>(1, back);
  const std::size_t n_recent = recent_heading_rad_.size();
  if (static_cast<std::size_t>(recent_count_) >= 3 + skip) {
    const std::size_t i0 = n_recent - skip - 3;
    double s = 0, c = 0;
    for (std::size_t i = i0; i < i0 + 3; ++i) {
      s += std::sin(recent_heading_rad_[i]);
      c += std::cos(recent_heading_rad_[i]);
    }
    const double mean = std::atan2(s, c);
    bool straight = true;
    for (std::size_t i = i0; i < i0 + 3; ++i)
      straight = straight && std::abs(std::remainder(recent_heading_rad_[i] - mean, kTwoPi)) <
                                 straight_deg * M_PI / 180.0;
    if (straight) {
      stand_in_rad_ = wrap_2pi(mean);
      have_stand_in_ = true;
    }
  }
}

void PoseSwitch::note_heading(double heading_rad) {
  for (std::size_t i = 0; i + 1 < recent_heading_rad_.size(); ++i)
    recent_heading_rad_[i] = recent_heading_rad_[i + 1];
  recent_heading_rad_.back() = heading_rad;
  recent_count_ = std::min(recent_count_ + 1, static_cast<int>(recent_heading_rad_.size()));
}

}  // namespace telltale::fusion
