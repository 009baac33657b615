#pragma once
/// \file
/// Streaming step detectors (SPEC section 4, seeds 004 and 003).
///
/// Every detector takes one ImuSample at a time (`update`) and says whether a step completed at
/// that sample. Input contract, shared by all of them:
/// - `t_s` strictly increasing (non-uniform rates from 25 to 400 Hz are fine); a sample whose time
///   does not advance, or whose accelerometer is NaN/Inf, is ignored and counted in Diagnostics;
/// - the gyro is optional: a NaN gyro means "no gyroscope" (accelerometer-only phone traces), and
///   the detectors that can use it fall back to their accelerometer conditions;
/// - the sensor axes may be in any orientation (magnitudes and the dominant gyro axis are used).
///
/// Mount: a foot-mounted sensor counts the steps of ITS foot (one per gait cycle of that foot);
/// a body-worn sensor (belt, pocket, phone in any pose) counts every step.
///
/// Memory: fixed-size ring buffers, no heap after construction.

#include <array>
#include <cstddef>
#include <memory>
#include <ranges>
#include <span>
#include <string_view>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

enum class StepMount { kFoot, kBody };

/// One detected step.
struct StepEvent {
  double t_s = 0.0;         ///< when the step happened (each detector's update() says which moment)
  double interval_s = 0.0;  ///< time since the previous step (0 for the first one)
};

/// Steps a detector holds before it reports them: a fixed ring, oldest first, each with the
/// detector's own note about it. Released in order, each with its interval from the last one
/// released.
template <class Note, std::size_t N>
class HeldSteps {
 public:
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool full() const { return size_ == N; }
  /// The i-th oldest (i < size()).
  [[nodiscard]] double t_s(std::size_t i) const { return ring_[(head_ + i) % N].t_s; }
  [[nodiscard]] const Note& note(std::size_t i) const { return ring_[(head_ + i) % N].note; }
  /// Holds a step (not when full(): the caller releases one first).
  void push(double t_s, const Note& note) {
    ring_[(head_ + size_) % N] = {t_s, note};
    ++size_;
  }
  /// The oldest is not a step after all.
  void drop_oldest() {
    head_ = (head_ + 1) % N;
    --size_;
  }
  /// The oldest out, as `event`.
  void release(StepEvent& event) {
    event.t_s = ring_[head_].t_s;
    event.interval_s = have_released_ ? event.t_s - last_released_t_s_ : 0.0;
    have_released_ = true;
    last_released_t_s_ = event.t_s;
    drop_oldest();
  }

 private:
  struct Entry {
    double t_s = 0.0;
    Note note{};
  };
  std::array<Entry, N> ring_{};
  std::size_t head_ = 0, size_ = 0;
  bool have_released_ = false;
  double last_released_t_s_ = 0.0;
};

/// The gate's counts (gate_imu_sample: NaN/Inf time or accelerometer, time not advancing; a
/// NaN gyro is not a rejection here) and the detector's own.
struct StepDiagnostics : ImuGateCounts {
  unsigned rejected_timing = 0;     ///< candidate steps refused by the time threshold
  unsigned rejected_amplitude = 0;  ///< candidate steps refused by the amplitude conditions
  unsigned rejected_handling = 0;   ///< candidate steps refused because the sensor was tilted
  bool gyro_used = false;           ///< the last accepted sample carried a finite gyro
};

/// Fixed-capacity sliding window over time that keeps the mean of its positive samples and the
/// mean of its negative samples (the adaptive thresholds of seed 004, eqs. (3)-(6)).
class SignedMeanWindow {
 public:
  static constexpr std::size_t kCapacity = 1024;  ///< 2.5 s at 400 Hz
  void reset();
  /// Adds (t, v) and drops samples older than t - window_s (or the oldest when full).
  void push(double t_s, double v, double window_s);
  [[nodiscard]] double positive_mean() const { return n_pos_ > 0.0 ? sum_pos_ / n_pos_ : 0.0; }
  [[nodiscard]] double negative_mean() const { return n_neg_ > 0.0 ? sum_neg_ / n_neg_ : 0.0; }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  void pop();
  std::array<double, kCapacity> t_{};
  std::array<double, kCapacity> v_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  double sum_pos_ = 0.0;
  double sum_neg_ = 0.0;
  double n_pos_ = 0.0;
  double n_neg_ = 0.0;
};

/// How far the sensor tilted over the last second: the angle between the mean specific force
/// of the last second and that of the second before (both in the sensor's frame), from sums over
/// fixed blocks of time (the current block, still filling, is not read). Carried while walking,
/// a phone keeps its mean orientation: a stride's swing averages out over a second, and turning
/// about the vertical leaves gravity where it was in the sensor's frame; taken out of a pocket
/// or a bag, turned over in the hand, it tilts by tens of degrees in that second. Any sample
/// rate (the blocks are in seconds); a gap leaves empty blocks, which read as "no evidence" (0).
class TiltWindow {
 public:
  static constexpr std::size_t kBlocksPerSecond = 4;
  /// (Eigen's vectors are not zeroed by `{}`: the ring is, so that copying a fresh window (a
  /// detector's reset) copies values.)
  TiltWindow() { blocks_.fill(Eigen::Vector3d::Zero()); }
  void add(double t_s, const Eigen::Vector3d& f);
  /// The angle (rad) between the two seconds' mean directions (before two seconds are in: the
  /// two halves of what is there); 0 before two blocks.
  [[nodiscard]] double angle_rad() const;

 private:
  static constexpr std::size_t kBlocks = 2 * kBlocksPerSecond;
  std::array<Eigen::Vector3d, kBlocks> blocks_;    ///< sum of f per block, ring
  std::size_t head_ = 0;                           ///< the oldest block
  std::size_t filled_ = 0;
  Eigen::Vector3d current_ = Eigen::Vector3d::Zero();
  double block_end_s_ = 0.0;
  bool started_ = false;
};

/// Two cascaded first-order low-pass sections with a time constant, valid for non-uniform dt.
class LowPass2 {
 public:
  explicit LowPass2(double cutoff_hz = 3.0) : cutoff_hz_(cutoff_hz) {}
  double step(double x, double dt_s);
  void reset() { init_ = false; }

 private:
  double cutoff_hz_;
  double y1_ = 0.0;
  double y2_ = 0.0;
  bool init_ = false;
};

/// The interface every step detector implements (registry: make_step_detector).
class StepDetector {
 public:
  virtual ~StepDetector() = default;
  /// Feeds one sample. Returns true and fills `event` when a step is reported at this sample
  /// (peak-valley on a phone reports each a second after confirming it: see its Params). The
  /// detector sees the time on its LocalClock (the same steps whatever the time origin);
  /// `event.t_s` is on the caller's.
  bool update(const ImuSample& sample, StepEvent& event) {
    ImuSample local = sample;
    local.t_s = clock_.to_local(sample.t_s);
    if (!on_sample(local, event)) return false;
    event.t_s = clock_.to_caller(event.t_s);
    return true;
  }
  /// The end of the stream: returns true and fills `event` while steps are still held (call
  /// until false). Only a detector that holds steps has any.
  bool flush(StepEvent& event) {
    if (!on_flush(event)) return false;
    event.t_s = clock_.to_caller(event.t_s);
    return true;
  }
  /// Back to the state before the first sample (the clock's origin too: each detector's reset
  /// assigns a new detector to itself).
  virtual void reset() = 0;
  [[nodiscard]] virtual std::string_view name() const = 0;
  [[nodiscard]] virtual const StepDiagnostics& diagnostics() const = 0;

 protected:
  /// Every detector's use of the one IMU gate (gate_imu_sample): finite time and accelerometer,
  /// time advancing; the gyro may be missing (the detectors that use it check gyro_finite).
  /// Returns dt (0 on the first sample) or a negative value when the sample must be ignored.
  static double gate(const ImuSample& s, bool& have_t, double& last_t, StepDiagnostics& diag);
  /// update() and flush() of each detector, on its local time.
  virtual bool on_sample(const ImuSample& sample, StepEvent& event) = 0;
  virtual bool on_flush(StepEvent& /*event*/) { return false; }

 private:
  LocalClock clock_;
};

/// Runs `detector` over a whole stream of samples and its end: `on_step(event)` for every step
/// it reports, in order, the ones flush() releases at the end included. The one way to read a
/// recording through a detector (a loop without the flush loses the steps still held).
template <std::ranges::input_range Samples, class OnStep>
void for_each_step(StepDetector& detector, Samples&& samples, OnStep&& on_step) {
  StepEvent event;
  for (const ImuSample& s : samples)
    if (detector.update(s, event)) on_step(event);
  while (detector.flush(event)) on_step(event);
}

/// Seed 004: multi-source adaptive thresholds. Over a sliding window, upper/lower acceleration
/// thresholds are the means of the positive/negative samples of the dynamic specific-force
/// magnitude (|f| - g), and upper/lower angular-rate thresholds the same on the dominant gyro axis.
/// A step counts when, since the previous step, the acceleration has exceeded its upper and gone
/// below its lower threshold, the angular rate likewise (eq. (7): all four), the cycle has closed
/// (foot: the foot then rests for `stance_s`; body: the acceleration falls below its lower
/// threshold after the upper one) and the time thresholds hold (interval >=
/// `min_interval_fraction` x recent interval and >= `min_interval_s`). Without a gyro the two
/// acceleration conditions, the closing and the time thresholds remain.
struct AdaptiveStepParams {
  double window_s = 2.0;               ///< sliding window of the adaptive thresholds, s
  double acc_cutoff_hz = 12.0;         ///< low-pass on |f| before thresholding, Hz
  double gyro_cutoff_hz = 12.0;        ///< low-pass on the gyro axis, Hz
  double acc_floor_m_s2 = 1.0;         ///< thresholds never come closer to 0 than this, m/s^2
  double gyro_floor_rad_s = 0.5;       ///< same for the angular rate, rad/s
  double min_interval_s = 0.36;        ///< absolute time threshold, s (foot: 2.8 cycles/s max)
  double max_interval_s = 3.0;         ///< beyond this the cadence memory is reset, s
  double min_interval_fraction = 0.5;  ///< time threshold relative to the recent interval
  double initial_interval_s = 1.0;     ///< cadence memory at start, s
  double mean_tau_s = 4.0;             ///< time constant of the |f| mean the signal is taken about
  bool use_gyro = true;                ///< false: acceleration conditions only
  bool require_stance = true;          ///< foot: a cycle closes with the foot at rest
  double stance_s = 0.03;              ///< rest needed to close a foot cycle, s
  double stance_fraction = 0.25;       ///< rest = |f|-g and |w| below this x upper thresholds
};
class AdaptiveStepDetector final : public StepDetector {
 public:
  using Params = AdaptiveStepParams;
  explicit AdaptiveStepDetector(Params params = {});
  void reset() override;
  [[nodiscard]] std::string_view name() const override { return "adaptive"; }
  [[nodiscard]] const StepDiagnostics& diagnostics() const override { return diag_; }
  /// Current thresholds (eqs. (3)-(6)): acc upper/lower (m/s^2), gyro upper/lower (rad/s).
  [[nodiscard]] std::array<double, 4> thresholds() const;

 private:
  bool on_sample(const ImuSample& sample, StepEvent& event) override;
  Params params_;
  StepDiagnostics diag_;
  SignedMeanWindow acc_window_;
  SignedMeanWindow gyro_window_;
  LowPass2 acc_lp_;
  LowPass2 gyro_lp_;
  Eigen::Vector3d gyro_energy_ = Eigen::Vector3d::Zero();
  double g_est_m_s2_ = kStandardGravity_m_s2;
  double last_t_s_ = 0.0;
  double last_step_t_s_ = -1e9;
  double interval_ema_s_ = 1.0;
  double quiet_since_s_ = -1.0;
  bool have_t_ = false;
  bool have_step_ = false;
  std::array<bool, 4> seen_{};  ///< acc>up, acc<lo, gyro>up, gyro<lo since the last step
};

/// Baseline: peaks of the low-passed |f| above a fixed height, at least a fixed time apart
/// (the "peak detection" column of seed 004, Table 2). Parameters suit a normal walk.
struct PeakStepParams {
  double cutoff_hz = 5.0;         ///< low-pass on |f|, Hz
  double min_height_m_s2 = 11.5;  ///< a peak must exceed this |f|, m/s^2
  double min_distance_s = 0.3;    ///< peaks closer than this are merged, s
};
class PeakStepDetector final : public StepDetector {
 public:
  using Params = PeakStepParams;
  explicit PeakStepDetector(Params params = {});
  void reset() override;
  [[nodiscard]] std::string_view name() const override { return "peak"; }
  [[nodiscard]] const StepDiagnostics& diagnostics() const override { return diag_; }

 private:
  bool on_sample(const ImuSample& sample, StepEvent& event) override;
  Params params_;
  StepDiagnostics diag_;
  LowPass2 lp_;
  double y1_ = 0.0, y2_ = 0.0, t1_ = 0.0;
  int n_ = 0;
  double last_t_s_ = 0.0;
  double last_step_t_s_ = -1e9;
};

/// Baseline: rising crossings of a fixed |f| threshold with a refractory time ("fixed threshold").
struct FixedThresholdStepParams {
  double cutoff_hz = 5.0;        ///< low-pass on |f|, Hz
  double threshold_m_s2 = 11.5;  ///< rising crossing of this |f| counts, m/s^2
  double hysteresis_m_s2 = 1.0;  ///< must fall below threshold - hysteresis to re-arm, m/s^2
  double refractory_s = 0.3;     ///< minimum time between steps, s
};
class FixedThresholdStepDetector final : public StepDetector {
 public:
  using Params = FixedThresholdStepParams;
  explicit FixedThresholdStepDetector(Params params = {});
  void reset() override;
  [[nodiscard]] std::string_view name() const override { return "fixed-threshold"; }
  [[nodiscard]] const StepDiagnostics& diagnostics() const override { return diag_; }

 private:
  bool on_sample(const ImuSample& sample, StepEvent& event) override;
  Params params_;
  StepDiagnostics diag_;
  LowPass2 lp_;
  bool armed_ = true;
  bool have_t_ = false;
  double last_t_s_ = 0.0;
  double last_step_t_s_ = -1e9;
};

/// Steps from a swinging arm (a phone carried in the hand, arm swinging): the arm turns forward
/// and back once per stride, so its rate about the swing axis changes sign at each end of the
/// swing, once per step. The body's acceleration magnitude is no help there: the hand's pendulum
/// (10-25 m/s^2) swamps the trunk's and the peak-valley detector loses steps at a fast pace.
/// A sign change counts once the rate has gone past `peak_fraction` of the previous half swing's
/// peak the other way (and past `min_rate_rad_s`). A hand that only wobbles (held in front of
/// the face, or to the ear: a few degrees, though at up to ~1 rad/s) is not a swing: `swinging`
/// says whether the phone swings, by the angle each half swing sweeps (an arm: 2 x 16-40 deg).
/// The last half swing of a walk ends at rest, not at a turn: a swinging phone that comes to rest
/// (the rate under `min_rate_rad_s` for `rest_s`) after half a swing has made its last step.
struct SwingStepParams {
  double min_rate_rad_s = 0.5;   ///< smallest rate that starts a half swing, rad/s
  double min_sweep_deg = 20.0;   ///< smallest angle a half swing of a swinging arm sweeps
  double peak_fraction = 0.3;    ///< hysteresis relative to the last half swing's peak
  double min_interval_s = 0.25;  ///< shortest step, s (4 steps/s)
  double max_interval_s = 1.5;   ///< a longer half swing is no walk: the memory is reset
  double rest_s = 0.35;          ///< at rest (a turn passes under min_rate in 0.1-0.2 s)
  double axis_tau_s = 1.0;       ///< memory of the swing axis, s
};
class SwingStepDetector {
 public:
  using Params = SwingStepParams;
  explicit SwingStepDetector(Params params = {}) : params_(params) {}
  /// The angular rate's horizontal part (any frame fixed in the phone; NaN: ignored). The swing
  /// axis is its principal direction over the last `axis_tau_s`, found whatever the pose.
  /// True when a step completed.
  bool update(double t_s, const Eigen::Vector3d& horizontal_rate_rad_s);
  /// When the last step completed: the turn (the sample it was confirmed at), or for the last
  /// step of a walk the moment the phone came to rest (confirmed rest_s later).
  [[nodiscard]] double step_t_s() const { return step_t_s_; }
  /// How long the last completed half swing took (a step), s; 0 before one completed.
  [[nodiscard]] double half_swing_s() const { return half_swing_s_; }
  /// The phone swings: the last two completed half swings swept min_sweep_deg or more each and
  /// the last turn was less than max_interval_s before t_s.
  [[nodiscard]] bool swinging(double t_s) const;
  void reset() { *this = SwingStepDetector(params_); }

 private:
  /// The step logic on the rate about the swing axis.
  bool on_rate(double t_s, double dt, double rate);

  Params params_;
  int sign_ = 0;                         ///< the half swing in progress (0: none yet)
  double peak_ = 0.0;                    ///< its peak |rate|
  double sweep_rad_ = 0.0;               ///< the angle it swept so far
  int run_sign_ = 0;                     ///< the rate's sign...
  double run_rad_ = 0.0;                 ///< ...and the angle swept since it last crossed zero
  std::array<double, 2> done_sweeps_{};  ///< of the last two completed half swings, rad
  double since_s_ = 0.0;                 ///< start of the half swing in progress
  double last_t_s_ = 0.0;
  double slow_since_s_ = -1.0;  ///< the rate has been under min_rate_rad_s since (-1: it is not)
  double step_t_s_ = 0.0;
  double half_swing_s_ = 0.0;
  Eigen::Matrix3d rate_cov_ = Eigen::Matrix3d::Zero();  ///< of the horizontal rate, forgetting
  Eigen::Vector3d axis_ = Eigen::Vector3d::UnitY();     ///< its principal direction
  bool have_t_ = false;
};

/// Names accepted by make_step_detector: "adaptive", "peak", "fixed-threshold", "peak-valley",
/// "gait-phase".
[[nodiscard]] std::span<const std::string_view> step_detector_names();
/// The default detector for a mount: foot -> "gait-phase", body -> "peak-valley" (a phone: any
/// pose; for a sensor rigid to the trunk, "gait-phase" counts better).
[[nodiscard]] std::string_view default_step_detector(StepMount mount);
/// Builds a detector with defaults suited to the mount; nullptr for an unknown name.
[[nodiscard]] std::unique_ptr<StepDetector> make_step_detector(std::string_view name,
                                                               StepMount mount);

}  // namespace telltale::fusion
