// Closed-loop hierarchical heading fusion (paper 002, eq. 1-37) and its baselines.
//
// Where the paper is open or inconsistent, and what this file does (numbers in
// notes/issue-4.md, proofs in tests/unit/heading_fusion_test.cpp):
//
// 1. Feedback covariance, eq. 11/37. Printed: p_i^+(k) = beta_i P^+(k) with beta_i <= 1 (eq. 36),
//    i.e. every local filter is told it is N times MORE certain than the global one. The
//    "information sharing principle" the paper invokes (the federated filter) splits the
//    information, not the covariance: p_i = P / beta_i, and the local process noise q / beta_i
//    with it, so that eq. 4 gives p_i^-(k) = P^-(k) / beta_i. We do that ("closed-loop"). The
//    printed form is kept as "closed-loop-eq27" and "closed-loop-paper".
// 2. beta_i from tr(p_i), eq. 35-36: we read p_i as the local posterior p_i^+ of eq. 9 (eq. 18
//    uses the same letter for a correction term, whose trace grows with the gain). With the
//    resolutions below the result does not depend on beta at all (see the end of this note);
//    it still sets the local covariances p_i = P / beta_i that lambda_i is built from.
// 3. lambda_i, eq. 32-33. Printed: lambda_i = P^+^-1 M_i p_i^+, multiplying k_i y_i, while
//    E (eq. 28) keeps k_i without lambda. Then X^+ = E X^+(k-1) + D sum lambda_i k_i y_i is not
//    unbiased: for a constant heading psi its fixed point is not psi unless
//    D sum lambda_i k_i h = D sum k_i h, and since lambda_i ~ P^-^-1 p_i^- != I the estimate is
//    pulled towards 0 deg (the bias scales with the absolute heading, a wrap makes it jump). It
//    also weights a sensor by its covariance, not its information. We use the normalised
//    information ratio lambda_i = m (sum_j M_j p_j^+^-1)^-1 M_i p_i^+^-1 (m = sum M_i, so
//    D sum lambda_i = I) and put it in E as well, which is eq. 33 written in innovation form:
//    X^+ = X^- + D sum lambda_i k_i (y_i - h X^-).
// 4. Eq. 21 is the covariance of the optimal gain only; we compute P^+ for the gain actually
//    used with the Joseph form, so the covariance stays honest whatever the gain.
// With 1-3, "closed-loop" IS the centralized filter (the paper's own claim, end of 2.3), for
// any shares with sum beta_i = 1 over the fused set, whatever the r_i: in information form
// p_i^+^-1 = beta_i P^-^-1 + h^T h / r_i and p_i^+^-1 k_i = h^T / r_i, so
// sum_j p_j^+^-1 = P^-^-1 + sum_j h^T h / r_j = (P_c^+)^-1 and
// sum_i D lambda_i k_i nu_i = P_c^+ sum_i h^T nu_i / r_i, the centralized update. Measured
// difference on every simulated scenario: < 2e-13 deg. The local/global structure costs time
// (see the benchmark) and buys nothing in a single process; it matters only where the local
// filters run on separate computers, which a boat node does not do.
#include "telltale/fusion/heading_fusion.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace telltale::fusion {
namespace {

using Vec2 = HeadingFusion::Vec2;
using Mat2 = HeadingFusion::Mat2;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool has_bit(std::uint16_t mask, int i) { return ((static_cast<unsigned>(mask) >> i) & 1u) != 0; }

Mat2 symmetrised(const Mat2& p) { return 0.5 * (p + p.transpose()); }

/// Circular mean of the finite readings, deg in [0, 360); NaN if none.
double circular_mean_deg(const double* y, int n) {
  double s = 0.0;
  double c = 0.0;
  int k = 0;
  constexpr double kRad = M_PI / 180.0;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(y[i])) continue;
    s += std::sin(y[i] * kRad);
    c += std::cos(y[i] * kRad);
    ++k;
  }
  if (k == 0 || (s == 0.0 && c == 0.0)) return kNaN;
  return wrap_360_deg(std::atan2(s, c) / kRad);
}

}  // namespace

std::string_view heading_method_name(HeadingMethod m) {
  switch (m) {
    case HeadingMethod::kClosedLoop:
      return "closed-loop";
    case HeadingMethod::kClosedLoopPaper:
      return "closed-loop-paper";
    case HeadingMethod::kClosedLoopEq27:
      return "closed-loop-eq27";
    case HeadingMethod::kDistributed:
      return "distributed";
    case HeadingMethod::kCentralized:
      return "centralized";
    case HeadingMethod::kAverage:
      return "average";
    case HeadingMethod::kBestSingle:
      return "best-single";
  }
  return "unknown";
}

std::optional<HeadingMethod> heading_method_from_name(std::string_view name) {
  for (HeadingMethod m : kAllHeadingMethods) {
    if (heading_method_name(m) == name) return m;
  }
  return std::nullopt;
}

HeadingFusion::HeadingFusion(Params params)
    : params_(params),
      n_(std::clamp(params.sensor_count, 1, kMaxHeadingSensors)),
      monitor_(params.monitor) {
  for (int i = 0; i < n_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const double sd = params_.noise_deg[ui];
    // A zero or invalid noise would make a singular gain; 1e-3 deg is below any real compass.
    r_deg2_[ui] = std::isfinite(sd) && sd > 1e-3 ? sd * sd : 1e-6;
    if (r_deg2_[ui] < r_deg2_[static_cast<std::size_t>(best_sensor_)]) best_sensor_ = i;
  }
  if (!(params_.accel_var_deg2_s4 >= 0.0)) params_.accel_var_deg2_s4 = 0.0;
}

double HeadingFusion::heading_var_deg2() const {
  return params_.method == HeadingMethod::kAverage ? kNaN : state_.p(0, 0);
}

void HeadingFusion::initialise(double t_s, const double* y) {
  double h = kNaN;
  if (params_.method == HeadingMethod::kBestSingle) h = y[best_sensor_];
  if (!std::isfinite(h)) h = circular_mean_deg(y, n_);
  if (!std::isfinite(h)) return;
  double r_mean = 0.0;
  for (int i = 0; i < n_; ++i) r_mean += r_deg2_[static_cast<std::size_t>(i)];
  r_mean /= n_;
  state_.x = Vec2(wrap_360_deg(h), 0.0);
  state_.p = Mat2::Zero();
  state_.p(0, 0) = r_mean;
  state_.p(1, 1) = params_.initial_rate_var_deg2_s2;
  for (int i = 0; i < n_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    state_.local_x[ui] = state_.x;
    if (std::isfinite(y[i])) state_.local_x[ui](0) = state_.x(0) + wrap_180_deg(y[i] - state_.x(0));
    state_.local_p[ui] = state_.p;
    state_.local_p[ui](0, 0) = r_deg2_[ui];
    state_.local_trace[ui] = r_deg2_[ui];  // starts beta at its fixed point (note 2 above)
    state_.beta[ui] = 1.0 / n_;
  }
  state_.last_t_s = t_s;
  state_.initialised = true;
}

void HeadingFusion::predict(double dt_s) {
  // Paper eq. 39 generalised to the step actually elapsed: F = [1 dt; 0 1], G = [0; dt].
  f_ << 1.0, dt_s, 0.0, 1.0;
  gqg_ = Mat2::Zero();
  gqg_(1, 1) = dt_s * dt_s * params_.accel_var_deg2_s4;
  state_.x = f_ * state_.x;                                       // eq. 22
  p_prior_ = symmetrised(f_ * state_.p * f_.transpose() + gqg_);  // eq. 17
}

void HeadingFusion::update(double t_s, const double* readings_deg, const double* age_s) {
  ++diag_.updates;
  std::array<double, kMaxHeadingSensors> y;
  y.fill(kNaN);
  bool any = false;
  for (int i = 0; i < n_; ++i) {
    const double v = readings_deg[i];
    if (std::isinf(v)) ++diag_.rejected_non_finite;
    y[static_cast<std::size_t>(i)] = v;  // the monitor reports Inf; the algebra never sees it
    any = any || std::isfinite(v);
  }
  if (!std::isfinite(t_s)) {
    ++diag_.rejected_time;
    return;
  }
  if (state_.initialised) {
    const double dt = t_s - state_.last_t_s;
    if (!(dt > 0.0)) {
      ++diag_.rejected_time;
      return;
    }
    if (dt > params_.max_dt_s) {
      ++diag_.reinitialisations;
      state_.initialised = false;
    }
  }
  if (!state_.initialised) {
    if (!any) return;
    for (auto& v : y) {
      if (!std::isfinite(v)) v = kNaN;
    }
    initialise(t_s, y.data());
    diag_.sensors_in_use = 0;
    for (int i = 0; i < n_; ++i) {
      const bool in = std::isfinite(y[static_cast<std::size_t>(i)]);
      if (in) diag_.sensors_in_use = static_cast<std::uint16_t>(diag_.sensors_in_use | (1u << i));
      diag_.status[static_cast<std::size_t>(i)] =
          in ? HeadingSensorStatus::kInUse : HeadingSensorStatus::kNoReading;
    }
    monitor_.note_fused(heading_deg());
    return;
  }

  const double dt = t_s - state_.last_t_s;
  state_.last_t_s = t_s;
  predict(dt);

  // Latency: a reading that is latency_s old saw the heading of latency_s ago. The compensation
  // uses the estimated rate, so its uncertainty adds latency^2 var(rate) to the reading's noise.
  for (int i = 0; i < n_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const double age =
        (age_s != nullptr && std::isfinite(age_s[i]) && age_s[i] > 0.0) ? age_s[i] : 0.0;
    const double lat = params_.latency_s[ui] + age;
    if (std::isfinite(y[ui])) y[ui] += state_.x(1) * lat;
    r_eff_deg2_[ui] = r_deg2_[ui] + lat * lat * p_prior_(1, 1);
  }

  // Should I fuse? (heading_monitor.hpp) — separate from how (below).
  std::uint16_t mask = 0;
  diag_.model_mismatch = false;
  diag_.sensors_disagree = false;
  const bool gated =
      params_.method != HeadingMethod::kAverage && params_.method != HeadingMethod::kBestSingle;
  if (gated) {
    const HeadingGateDecision d = monitor_.assess(t_s, dt, n_, y.data(), r_eff_deg2_.data(),
                                                  state_.x(0), p_prior_(0, 0), diag_.status.data());
    mask = d.use_mask;
    diag_.model_mismatch = d.model_mismatch;
    diag_.sensors_disagree = d.sensors_disagree;
    if (d.model_mismatch) ++diag_.model_mismatches;
    if (d.covariance_inflation > 1.0) p_prior_ *= d.covariance_inflation;
  } else {
    for (int i = 0; i < n_; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      const bool in =
          std::isfinite(y[ui]) && (params_.method == HeadingMethod::kAverage || i == best_sensor_);
      if (in) mask = static_cast<std::uint16_t>(mask | (1u << i));
      diag_.status[ui] = in ? HeadingSensorStatus::kInUse
                            : (std::isinf(y[ui]) ? HeadingSensorStatus::kNonFinite
                                                 : HeadingSensorStatus::kNoReading);
    }
  }
  for (auto& v : y) {
    if (!std::isfinite(v)) v = kNaN;
  }

  switch (params_.method) {
    case HeadingMethod::kCentralized:
      fuse_centralized(y.data(), mask);
      break;
    case HeadingMethod::kClosedLoop:
    case HeadingMethod::kClosedLoopPaper:
    case HeadingMethod::kClosedLoopEq27:
      fuse_closed_loop(y.data(), mask);
      break;
    case HeadingMethod::kDistributed:
      fuse_distributed(y.data(), mask, dt);
      break;
    case HeadingMethod::kBestSingle:
      fuse_best_single(y.data(), dt);
      break;
    case HeadingMethod::kAverage:
      fuse_average(y.data());
      break;
  }
  normalise_heading();
  monitor_.note_fused(heading_deg());

  diag_.sensors_in_use = mask;
  const std::uint16_t was_excluded = diag_.sensors_excluded;
  diag_.sensors_excluded = 0;
  for (int i = 0; i < n_; ++i) {
    const HeadingSensorStatus s = diag_.status[static_cast<std::size_t>(i)];
    if (s == HeadingSensorStatus::kInconsistent || s == HeadingSensorStatus::kFrozen ||
        s == HeadingSensorStatus::kSilent || s == HeadingSensorStatus::kRecovering) {
      diag_.sensors_excluded = static_cast<std::uint16_t>(diag_.sensors_excluded | (1u << i));
    }
  }
  diag_.exclusions += static_cast<std::uint64_t>(
      std::popcount(static_cast<unsigned>(diag_.sensors_excluded & ~was_excluded)));
  diag_.coasting = mask == 0;
}

void HeadingFusion::fuse_centralized(const double* y, std::uint16_t mask) {
  // Augmented measurement Y = [y_1 .. y_m], C = [h; ..; h], R = diag(r_i): with a diagonal R the
  // batch update equals m scalar updates in sequence (exactly, in exact arithmetic).
  Mat2 p = p_prior_;
  Vec2 x = state_.x;
  for (int i = 0; i < n_; ++i) {
    if (!has_bit(mask, i)) continue;
    const double nu = wrap_180_deg(y[i] - x(0));
    const double s = p(0, 0) + r_eff_deg2_[static_cast<std::size_t>(i)];
    const Vec2 k = p.col(0) / s;
    x += k * nu;
    p = symmetrised(p - k * p.row(0));
  }
  state_.x = x;
  state_.p = p;
}

void HeadingFusion::fuse_closed_loop(const double* y, std::uint16_t mask) {
  const HeadingMethod method = params_.method;
  const bool literal = method != HeadingMethod::kClosedLoop;
  const Vec2 x_prior = state_.x;  // X^-(k) = F X^+(k-1), eq. 22; also x_i^-(k) by eq. 3 + 10
  int m = 0;
  double inv_trace_sum = 0.0;
  for (int i = 0; i < n_; ++i) {
    if (!has_bit(mask, i)) continue;
    ++m;
    inv_trace_sum += 1.0 / state_.local_trace[static_cast<std::size_t>(i)];
  }
  if (m == 0) {  // every M_i = 0: prediction only
    state_.p = p_prior_;
    return;
  }
  const double rho = 1.0 / inv_trace_sum;  // eq. 35
  const double d = 1.0 / m;                // D = (sum M_i)^-1, eq. 20 (M_i = I or 0)

  std::array<Vec2, kMaxHeadingSensors> k{};
  std::array<Mat2, kMaxHeadingSensors> p_post{};
  std::array<double, kMaxHeadingSensors> nu{};
  Mat2 info_sum = Mat2::Zero();
  Mat2 sum_kc = Mat2::Zero();
  for (int i = 0; i < n_; ++i) {
    if (!has_bit(mask, i)) continue;
    const auto ui = static_cast<std::size_t>(i);
    const double beta = rho / state_.local_trace[ui];  // eq. 36
    state_.beta[ui] = beta;
    // Local time update, eq. 3-4, started from the fed-back global estimate (eq. 10-11).
    const Mat2 p_minus =
        literal ? Mat2(beta * (p_prior_ - gqg_) + gqg_)  // eq. 4 with p_i^+ = beta P^+ (eq. 11)
                : Mat2(p_prior_ / beta);                 // p_i^+ = P^+/beta, q_i = q/beta
    nu[ui] = wrap_180_deg(y[i] - x_prior(0));            // eq. 5 = eq. 23
    const double s = p_minus(0, 0) + r_eff_deg2_[ui];    // eq. 6
    k[ui] = p_minus.col(0) / s;                          // eq. 7
    p_post[ui] = symmetrised(p_minus - k[ui] * p_minus.row(0));  // eq. 9
    state_.local_trace[ui] = p_post[ui].trace();
    sum_kc.col(0) += k[ui];  // sum k_i c_i, c_i = h M_i (eq. 16)
    if (!literal) info_sum += p_post[ui].inverse();
  }

  if (method == HeadingMethod::kClosedLoop) {
    // Note 3: lambda_i = m (sum_j p_j^+^-1)^-1 p_i^+^-1, so D lambda_i = (sum)^-1 p_i^+^-1.
    const Mat2 info_cov = info_sum.inverse();
    Vec2 dx = Vec2::Zero();
    Mat2 a = Mat2::Identity();
    Mat2 noise = Mat2::Zero();
    for (int i = 0; i < n_; ++i) {
      if (!has_bit(mask, i)) continue;
      const auto ui = static_cast<std::size_t>(i);
      const Vec2 gain = info_cov * p_post[ui].inverse() * k[ui];  // D lambda_i k_i
      dx += gain * nu[ui];                                        // eq. 33, innovation form
      a.col(0) -= gain;
      noise += gain * r_eff_deg2_[ui] * gain.transpose();
    }
    state_.x = x_prior + dx;
    state_.p = symmetrised(a * p_prior_ * a.transpose() + noise);  // Joseph form (note 4)
    return;
  }

  const Mat2 i_minus_dkc = Mat2::Identity() - d * sum_kc;
  state_.p = symmetrised(i_minus_dkc * p_prior_);  // eq. 21
  if (method == HeadingMethod::kClosedLoopEq27) {
    Vec2 dx = Vec2::Zero();
    for (int i = 0; i < n_; ++i) {
      if (has_bit(mask, i)) dx += k[static_cast<std::size_t>(i)] * nu[static_cast<std::size_t>(i)];
    }
    state_.x = x_prior + d * dx;  // eq. 24-27
    return;
  }
  // As printed: X^+ = E X^+(k-1) + D sum lambda_i k_i y_i, E = (I - D sum k_i c_i) F
  // (eq. 28, 32, 33), with x_i^+(k) - alpha_i x_i^+(k-1) = k_i y_i (eq. 31). y_i is taken on the
  // same turn as X^- so that the wrap is not an extra error.
  const Mat2 p_inv = state_.p.inverse();
  Vec2 meas = Vec2::Zero();
  for (int i = 0; i < n_; ++i) {
    if (!has_bit(mask, i)) continue;
    const auto ui = static_cast<std::size_t>(i);
    const Mat2 lambda = p_inv * p_post[ui];  // eq. 32
    meas += lambda * k[ui] * (x_prior(0) + nu[ui]);
  }
  state_.x = i_minus_dkc * x_prior + d * meas;
  if (!state_.x.allFinite()) state_.x = x_prior;  // keep the state finite whatever eq. 33 does
}

void HeadingFusion::fuse_distributed(const double* y, std::uint16_t mask, double dt_s) {
  // Reference [17]'s distributed fusion: N independent local KFs (eq. 3-9, no feedback), fused
  // by their covariances, X = P sum p_i^-1 x_i, P = (sum p_i^-1)^-1 (cross-covariances ignored).
  (void)dt_s;
  const double inflation = p_prior_(0, 0) / (f_ * state_.p * f_.transpose() + gqg_)(0, 0);
  const Vec2 x_ref = state_.x;
  Mat2 info = Mat2::Zero();
  Vec2 info_x = Vec2::Zero();
  for (int i = 0; i < n_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    Vec2& xi = state_.local_x[ui];
    Mat2& pi = state_.local_p[ui];
    xi = f_ * xi;
    pi = symmetrised(f_ * pi * f_.transpose() + gqg_);
    if (diag_.model_mismatch && inflation > 1.0) pi *= inflation;
    if (!pi.allFinite() || !xi.allFinite() || pi(0, 0) > 1e6) {
      // A local filter that coasted for minutes knows nothing: re-seed it from the global one.
      xi = x_ref;
      pi = p_prior_;
    }
    if (has_bit(mask, i)) {
      const double nu = wrap_180_deg(y[i] - xi(0));
      const double s = pi(0, 0) + r_eff_deg2_[ui];
      const Vec2 k = pi.col(0) / s;
      xi += k * nu;
      pi = symmetrised(pi - k * pi.row(0));
    }
    const HeadingSensorStatus st = diag_.status[ui];
    const bool healthy = st == HeadingSensorStatus::kInUse ||
                         st == HeadingSensorStatus::kNoReading ||
                         st == HeadingSensorStatus::kSampleRejected;
    if (!healthy) continue;
    const Mat2 w = pi.inverse();
    Vec2 dxi = xi - x_ref;
    dxi(0) = wrap_180_deg(dxi(0));
    info += w;
    info_x += w * dxi;
  }
  if (info.determinant() <= 0.0) {
    state_.p = p_prior_;
    return;
  }
  state_.p = symmetrised(info.inverse());
  state_.x = x_ref + state_.p * info_x;
}

void HeadingFusion::fuse_best_single(const double* y, double dt_s) {
  (void)dt_s;
  state_.p = p_prior_;
  const double yb = y[best_sensor_];
  if (!std::isfinite(yb)) return;
  const double nu = wrap_180_deg(yb - state_.x(0));
  const double s = state_.p(0, 0) + r_eff_deg2_[static_cast<std::size_t>(best_sensor_)];
  const Vec2 k = state_.p.col(0) / s;
  state_.x += k * nu;
  state_.p = symmetrised(state_.p - k * state_.p.row(0));
}

void HeadingFusion::fuse_average(const double* y) {
  const double h = circular_mean_deg(y, n_);
  if (std::isfinite(h)) state_.x(0) = h;
  state_.x(1) = 0.0;
  state_.p = Mat2::Identity();
}

void HeadingFusion::normalise_heading() {
  const double turns = std::floor(state_.x(0) / 360.0);
  if (turns == 0.0 || !std::isfinite(turns)) return;
  state_.x(0) -= 360.0 * turns;
  for (int i = 0; i < n_; ++i) state_.local_x[static_cast<std::size_t>(i)](0) -= 360.0 * turns;
}

HeadingReadingBuffer::HeadingReadingBuffer(int sensor_count)
    : n_(std::clamp(sensor_count, 1, kMaxHeadingSensors)) {
  heading_deg_.fill(kNaN);
  t_s_.fill(kNaN);
}

void HeadingReadingBuffer::push(int sensor, double t_s, double heading_deg) {
  if (sensor < 0 || sensor >= n_ || !std::isfinite(heading_deg) || !std::isfinite(t_s)) {
    ++ignored_;
    return;
  }
  heading_deg_[static_cast<std::size_t>(sensor)] = heading_deg;
  t_s_[static_cast<std::size_t>(sensor)] = t_s;
}

void HeadingReadingBuffer::flush_into(HeadingFusion& fusion, double t_s) {
  std::array<double, kMaxHeadingSensors> age{};
  for (int i = 0; i < n_; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    age[ui] = std::isfinite(t_s_[ui]) ? std::max(0.0, t_s - t_s_[ui]) : 0.0;
  }
  fusion.update(t_s, heading_deg_.data(), age.data());
  heading_deg_.fill(kNaN);
  t_s_.fill(kNaN);
}

}  // namespace telltale::fusion
