#pragma once
/// \file
/// Fusion of N redundant heading sensors (gyrocompass, magnetic compass, GNSS heading):
/// the closed-loop hierarchical fusion of paper 002 (Xu & Lin, Acta Electronica Sinica 2014,
/// eq. 1-37) and the baselines it is measured against, one class, methods chosen by name.
///
/// Model (paper eq. 38-40): state x = [psi_deg, r_deg_s] (heading, turn rate),
/// F = [[1, dt], [0, 1]], G = [0, dt]^T, process noise w = yaw acceleration with variance
/// `accel_var_deg2_s4`; every sensor observes h_i = [1, 0] with noise variance noise_deg_i^2.
/// The paper's test is dt = 0.1 s, Q = 0.3, r_i = 0.01 (HeadingFusionParams::paper()).
/// Units are degrees because the paper's Q and r_i are; the names say so.
///
/// Heading wraps at 360: every innovation is wrapped to [-180, 180) and the state heading is
/// kept in [0, 360) by shifting all (global and local) states by the same multiple of 360, so
/// crossing north never makes a jump or a bias.
///
/// Usage (boat node):
///   HeadingFusion fusion(params);                        // params.sensor_count = N
///   std::array<double, kMaxHeadingSensors> y;  y.fill(NAN);  y[i] = reading_i_deg;
///   fusion.update(t_s, y.data());                        // NaN = no reading from sensor i now
///   fusion.heading_deg(); fusion.diagnostics().sensors_in_use;  // bit i = sensor i fused
/// Call order: update() with strictly increasing t_s; the first call with at least one reading
/// initialises the state. A reading taken `latency_s[i]` before t_s is compensated with the
/// estimated turn rate. No heap, no exceptions, NaN/Inf never enter the state.
///
/// Which sensor to fuse (M_i) is decided by HeadingSensorMonitor (heading_monitor.hpp), not here.

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/heading_monitor.hpp"

namespace telltale::fusion {

/// Fusion methods, by name (heading_method_from_name). kClosedLoop is the default.
enum class HeadingMethod : std::uint8_t {
  kClosedLoop,       ///< "closed-loop": paper eq. 1-37 with the resolutions in heading_fusion.cpp
  kClosedLoopPaper,  ///< "closed-loop-paper": eq. 11 and 32-33 exactly as printed (biased, see
                     ///< note)
  kClosedLoopEq27,   ///< "closed-loop-eq27": eq. 11 as printed, eq. 27 (no lambda)
  kDistributed,      ///< "distributed": independent local KFs, covariance-weighted (federated, no
                     ///< reset)
  kCentralized,      ///< "centralized": augmented-measurement KF, the optimum
  kAverage,          ///< "average": circular mean of the readings present, no model, no gating
  kBestSingle,       ///< "best-single": one KF on the sensor with the smallest noise_deg
};

/// Every method, default first.
inline constexpr std::array<HeadingMethod, 7> kAllHeadingMethods = {
    HeadingMethod::kClosedLoop,  HeadingMethod::kClosedLoopPaper, HeadingMethod::kClosedLoopEq27,
    HeadingMethod::kDistributed, HeadingMethod::kCentralized,     HeadingMethod::kAverage,
    HeadingMethod::kBestSingle};
[[nodiscard]] std::string_view heading_method_name(HeadingMethod m);
[[nodiscard]] std::optional<HeadingMethod> heading_method_from_name(std::string_view name);

/// Settings of HeadingFusion. Defaults suit a dinghy (tacks of 90 deg in 4 s); paper() gives
/// the paper's test values.
struct HeadingFusionParams {
  int sensor_count = 3;  ///< N, 1..kMaxHeadingSensors
  HeadingMethod method = HeadingMethod::kClosedLoop;
  std::array<double, kMaxHeadingSensors> noise_deg{0.1, 0.1, 0.1, 0.1,
                                                   0.1, 0.1, 0.1, 0.1};  ///< sigma of v_i, deg
  std::array<double, kMaxHeadingSensors> latency_s{};  ///< age of a reading when it arrives, s
  /// Q: variance of yaw acceleration, (deg/s^2)^2. 1000 = (31.6 deg/s^2)^2 covers a dinghy's
  /// 90-degree tack in 4 s (peak 90 pi^2 / (2 * 4^2) = 27.8 deg/s^2); with 400 the rate lags in
  /// tacks and latency-compensated sensors disagree with undelayed ones (false isolations).
  double accel_var_deg2_s4 = 1000.0;
  double initial_rate_var_deg2_s2 = 100.0;  ///< P0 of the turn rate, (deg/s)^2
  double max_dt_s = 5.0;           ///< a longer gap re-initialises from the next readings, s
  HeadingMonitorParams monitor{};  ///< fault handling (monitor.enabled = false: fuse everything)

  /// The paper's test setup: N = 3, Q = 0.3, r_i = 0.01 (sigma 0.1 deg).
  [[nodiscard]] static HeadingFusionParams paper() {
    HeadingFusionParams p;
    p.accel_var_deg2_s4 = 0.3;
    p.initial_rate_var_deg2_s2 = 1.0;
    return p;
  }
};

class HeadingFusion {
 public:
  using Params = HeadingFusionParams;
  using Vec2 = Eigen::Vector2d;
  using Mat2 = Eigen::Matrix2d;
  struct State {
    Vec2 x = Vec2::Zero();      ///< global [heading_deg in [0,360), rate_deg_s] (X^+ of the paper)
    Mat2 p = Mat2::Identity();  ///< its covariance P^+ (deg^2, deg^2/s, deg^2/s^2)
    std::array<Vec2, kMaxHeadingSensors> local_x{};        ///< x_i^+ (distributed, best-single)
    std::array<Mat2, kMaxHeadingSensors> local_p{};        ///< p_i^+
    std::array<double, kMaxHeadingSensors> beta{};         ///< information share beta_i (eq. 36)
    std::array<double, kMaxHeadingSensors> local_trace{};  ///< tr(p_i^+) of the last fusion
    double last_t_s = 0.0;
    bool initialised = false;
  };
  struct Diagnostics {
    std::uint16_t sensors_in_use = 0;    ///< bit i: sensor i fused at the last update
    std::uint16_t sensors_excluded = 0;  ///< bit i: isolated by the monitor (reason in status)
    std::array<HeadingSensorStatus, kMaxHeadingSensors> status{};
    bool model_mismatch = false;    ///< last update: no sensor agreed with the motion model
    bool sensors_disagree = false;  ///< last update: two candidates disagreed, model decided
    bool coasting = false;          ///< last update: nothing fused, prediction only
    std::uint64_t updates = 0;
    std::uint64_t rejected_time = 0;        ///< update() calls with t_s not after the last
    std::uint64_t rejected_non_finite = 0;  ///< +-Inf readings (NaN is "no reading")
    std::uint64_t model_mismatches = 0;
    std::uint64_t reinitialisations = 0;
    std::uint64_t exclusions = 0;  ///< times a sensor went from fused to isolated
  };

  explicit HeadingFusion(Params params = {});

  /// One step at time t_s. `heading_deg` points to sensor_count readings, any range (wrapped
  /// here), NaN = no reading. Never throws, never allocates.
  /// `age_s` (optional, sensor_count entries): how long before t_s each reading was received;
  /// it adds to latency_s[i] in the compensation (for readings collected between two calls).
  void update(double t_s, const double* heading_deg, const double* age_s = nullptr);
  void update(double t_s, std::span<const double> heading_deg) { update(t_s, heading_deg.data()); }

  /// Fused heading in [0, 360), deg.
  [[nodiscard]] double heading_deg() const { return wrap_360_deg(state_.x(0)); }
  /// Fused turn rate, deg/s (0 for kAverage).
  [[nodiscard]] double rate_deg_s() const { return state_.x(1); }
  /// Variance of the fused heading, deg^2 (NaN for kAverage, which has none).
  [[nodiscard]] double heading_var_deg2() const;
  [[nodiscard]] bool initialised() const { return state_.initialised; }
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const Params& params() const { return params_; }
  [[nodiscard]] const HeadingSensorMonitor& monitor() const { return monitor_; }

 private:
  void initialise(double t_s, const double* y);
  void predict(double dt_s);
  void fuse_centralized(const double* y, std::uint16_t mask);
  void fuse_closed_loop(const double* y, std::uint16_t mask);
  void fuse_distributed(const double* y, std::uint16_t mask, double dt_s);
  void fuse_best_single(const double* y, double dt_s);
  void fuse_average(const double* y);
  void normalise_heading();

  Params params_;
  int n_;
  std::array<double, kMaxHeadingSensors> r_deg2_{};      ///< noise_deg^2
  std::array<double, kMaxHeadingSensors> r_eff_deg2_{};  ///< + latency^2 * var(rate), this step
  int best_sensor_ = 0;
  State state_;
  Diagnostics diag_;
  HeadingSensorMonitor monitor_;
  Mat2 p_prior_ = Mat2::Identity();  ///< P^-(k) of this step
  Mat2 gqg_ = Mat2::Zero();          ///< G Q G^T of this step
  Mat2 f_ = Mat2::Identity();        ///< F of this step
};

/// Collects asynchronous readings (one NMEA sentence at a time, from several threads via the
/// caller's lock) and hands them to HeadingFusion once per tick, so that the monitor sees the
/// sensors side by side. Latest reading per sensor wins; its age at the tick is compensated.
///   buffer.push(i, t_received_s, heading_deg);   // any time, any order of sensors
///   buffer.flush_into(fusion, t_tick_s);          // at the node's rate, e.g. 10-25 Hz
class HeadingReadingBuffer {
 public:
  explicit HeadingReadingBuffer(int sensor_count);
  /// Stores a reading of sensor i (0-based) received at t_s. Out-of-range i or a non-finite
  /// value is ignored (counted in ignored()).
  void push(int sensor, double t_s, double heading_deg);
  /// Calls fusion.update(t_s, ...) with the readings pushed since the last flush (the others
  /// NaN), each aged t_s - t_received (>= 0), and clears the buffer.
  void flush_into(HeadingFusion& fusion, double t_s);
  [[nodiscard]] std::uint64_t ignored() const { return ignored_; }

 private:
  int n_;
  std::array<double, kMaxHeadingSensors> heading_deg_{};
  std::array<double, kMaxHeadingSensors> t_s_{};
  std::uint64_t ignored_ = 0;
};

}  // namespace telltale::fusion
