#pragma once
/// \file
/// Hand-held phone PDR stage (HandheldPdr, handheld_pdr.hpp): steps from the vertical specific
/// force, counted only once the motion is a walk (a regular cadence with the phone's tilt
/// steady), so handling the phone, standing and pausing make no steps and no distance. Owns its
/// moving sums, the peak-valley search and the candidates of a run not yet confirmed.
///
/// Memory: fixed-size arrays, no heap.

#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// Steps from the vertical specific force (f . up - its 2 s mean, smoothed over 0.2 s): one step
/// per peak followed by a valley, the peak-to-valley swing at least `min_swing_m_s2`. Such peaks
/// also come from handling the phone and from a hand moving while the walker stands, so a peak
/// is only a candidate: the detector says "walking" once `confirm_steps` candidates in a row have
/// a walking cadence (intervals in [min_interval_s, max_interval_s], each within
/// `max_interval_ratio` of the one before: gait is regular, handling is not; a candidate out of
/// that rhythm begins a new run with the one before it, which may be a walk's first step after a
/// bounce of the hand while standing) with the phone's tilt
/// steady over them (up moved less than `max_tilt_deg` from their mean, the rate rms below
/// `max_gyro_rms_rad_s`: a phone held in front while walking; handling turns it). Then the held
/// candidates become steps, and every further candidate with a walking interval. A gap longer
/// than `pause_intervals` step intervals (or max_interval_s) ends the walk: a pause -- unless a
/// peak found within it still awaits its valley (a walk's closing step, whose loading may
/// settle slowly: its valley a second after its peak).
/// A walk from standing begins with the push of its first toe-off, which lifts the trunk, and
/// the phone with it, about one step interval before the first heel strike: a bounce in the
/// walk's rhythm, but a fraction of a heel strike's loading (0.07-0.39 of the walk's peaks on
/// the IPOL lower-back trials, where the first heel strike's is 0.47-1.1). So a run's first
/// candidate becomes a step only if its peak reaches `first_step_fraction` of the median of
/// the three after it (IPIN phone walks: the first candidates of 12 runs reach 0.65-1.2).
struct WalkStepParams {
  double smooth_s = 0.2;        ///< moving mean: a step's vertical bounce is 1.5-2.5 Hz
  double mean_s = 2.0;          ///< the specific force's mean over this is taken out (g, scale)
  double min_swing_m_s2 = 1.0;  ///< a hand-held phone's vertical swing per step: 1.5-6 m/s^2
  double min_interval_s = 0.3;  ///< 3.3 steps/s: faster than any walk
  double max_interval_s = 1.2;  ///< 50 steps/min: slower is not a walk
  double max_interval_ratio = 1.5;
  int confirm_steps = 4;  ///< two strides
  double max_tilt_deg = 20.0;
  double max_gyro_rms_rad_s = 1.5;
  double pause_intervals = 2.5;
  double first_step_fraction = 0.4;  ///< of the next three peaks' median (0: every candidate)
};
class WalkStepDetector {
 public:
  using Params = WalkStepParams;
  static constexpr int kMaxHeld = 16;
  struct Candidate {
    double t_s = 0.0;
    double interval_s = 0.0;  ///< since the previous candidate (0: first of a run)
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    double gyro_ms = 0.0;    ///< mean squared rate since the previous candidate
    double peak_m_s2 = 0.0;  ///< its peak of the smoothed vertical force, over its 2 s mean
  };
  struct State {
    // Moving sums (ring of the last mean_s of vertical force), sized for phones up to 400 Hz
    // (Android's fastest rate is 200-500 Hz): a full ring drops its oldest, so a faster stream
    // would shorten both windows. At 256 and 32 (2 s and 0.2 s at 128 / 160 Hz) the IPIN walks
    // resampled to 200 Hz counted 3 more steps each on route 01 and walked 4 % farther.
    static constexpr std::size_t kRing = 1024;
    static constexpr std::size_t kSm = 128;
    std::array<double, kRing> ring_t{}, ring_v{};
    std::size_t head = 0, size = 0;
    double sum_v = 0.0;
    std::array<double, kSm> sm_v{};  ///< last smoothing window of centred values
    std::array<double, kSm> sm_t{};
    std::size_t sm_head = 0, sm_size = 0;
    double sm_sum = 0.0;
    double prev_s = 0.0, prev2_s = 0.0, prev_t_s = 0.0;  ///< smoothed signal, two samples
    int have_prev = 0;
    // Peak-valley.
    bool have_peak = false;
    double peak_t_s = 0.0, peak_v = 0.0;
    Eigen::Vector3d peak_up = Eigen::Vector3d::UnitZ();
    double min_since_peak = 0.0;
    // Rate since the last candidate.
    double w2_sum = 0.0;
    int w2_n = 0;
    // Candidates of a run not yet confirmed.
    std::array<Candidate, kMaxHeld> held{};
    int held_n = 0;
    bool walking = false;
    double last_cand_t_s = -1e9;
    double interval_s = 0.0;  ///< the walk's current step interval (0: none yet)
  };
  explicit WalkStepDetector(Params p = {}) : params_(p) {}
  /// Feeds one sample with the up direction (unit, phone frame). Returns how many steps became
  /// known at this sample; their times are steps()[0..n).
  int update(const ImuSample& s, const Eigen::Vector3d& up);
  [[nodiscard]] const std::array<Candidate, kMaxHeld>& steps() const { return out_; }
  [[nodiscard]] bool walking() const { return state_.walking; }
  [[nodiscard]] double interval_s() const { return state_.interval_s; }
  [[nodiscard]] const State& state() const { return state_; }

 private:
  int on_candidate(const Candidate& c);
  bool run_is_walk() const;
  Params params_;
  State state_;
  std::array<Candidate, kMaxHeld> out_{};
};

}  // namespace telltale::fusion
