// Telltale's production heel/pitch filter. The contract and the ideas are in the header; here is
// why each step is done the way it is.
#include "telltale/fusion/attitude_telltale.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

namespace telltale::fusion {
namespace {

/// q * (quaternion of the rotation vector v (rad)), brought back to unit norm. The rotation's
/// quaternion dq = (c, s v), c = cos(|v|/2), s = sin(|v|/2) / |v|, is accurate to O(|v|^5)
/// without sin/cos: at 25 Hz and 5 rad/s |v| = 0.2 rad and the error is < 1e-6 rad per step.
Eigen::Quaterniond rotate_by(const Eigen::Quaterniond& q, const Eigen::Vector3d& v) {
  const double n = v.squaredNorm();
  const double n2 = n * n;
  // c = 1 - a2 / 2 + a2^2 / 24, s = 1 / 2 - a2 / 12 + a2^2 / 240 with a2 = n / 4.
  const double c = (1.0 - 0.125 * n) + n2 * (1.0 / 384.0);
  const double s = (0.5 - n * (1.0 / 48.0)) + n2 * (1.0 / 3840.0);
  const Eigen::Quaterniond p = q * Eigen::Quaterniond(0.0, v.x(), v.y(), v.z());
  Eigen::Quaterniond r;
  r.coeffs() = c * q.coeffs() + s * p.coeffs();
  // Back to unit norm without a square root (Newton step on |r|; the error e of |r|^2 = 1 + e
  // becomes O(e^2)). The quaternions here drift by ~1e-16 per step.
  r.coeffs() *= 1.5 - 0.5 * r.coeffs().squaredNorm();
  return r;
}

/// 2nd-order Butterworth low-pass, cut-off fc = sqrt(2) / (2 pi tau) (so that its step response
/// has the time constant tau), discretised for a step dt by the bilinear transform with
/// pre-warping: K = tan(pi fc dt) = tan(dt / (sqrt(2) tau)). The coefficients follow dt on every
/// sample (non-uniform sampling); tan by its series (x <= 0.24 for dt <= 1 s, tau = 3 s: the
/// x^7 term is < 2e-6 of the result), so no library call.
struct Butterworth {
  double b0, a1, a2;  // b1 = 2 b0, b2 = b0
};
Butterworth butterworth(double dt, double inv_sqrt2_tau) {
  const double x = dt * inv_sqrt2_tau;
  const double x2 = x * x;
  const double k = x * (1.0 + x2 * (1.0 / 3.0 + x2 * (2.0 / 15.0)));
  const double k2 = k * k;
  const double norm = 1.0 / (1.0 + M_SQRT2 * k + k2);
  return {k2 * norm, 2.0 * (k2 - 1.0) * norm, (1.0 - M_SQRT2 * k + k2) * norm};
}

/// One step of the Butterworth on the 21 low-passed values, in transposed direct form II:
///   y = b0 x + s0;  s0 = b1 x - a1 y + s1;  s1 = b2 x - a2 y  (b1 = 2 b0, b2 = b0).
/// The values are independent, so they go two at a time (one SIMD pair each) through all three
/// lines at once, each read and written once. As three Eigen assignments over the 3x5 blocks
/// (three passes, b0 x formed twice, the compiler making the assignment loop a call) it cost
/// ~340 instructions per update; this is ~195 fewer (callgrind). The same operations in the same
/// order on every value, so the same results bit for bit: b1 x = (2 b0) x is formed as
/// b0 x + b0 x (doubling is exact).
void butterworth_step(const Butterworth& c, const Eigen::Matrix<double, 3, 7>& x,
                      Eigen::Matrix<double, 3, 7>& y, Eigen::Matrix<double, 3, 7>& s0,
                      Eigen::Matrix<double, 3, 7>& s1) {
  using Pair = Eigen::Array2d;
  const double* xd = x.data();
  double* yd = y.data();
  double* s0d = s0.data();
  double* s1d = s1.data();
  for (int i = 0; i < 20; i += 2) {
    const Pair bx = c.b0 * Eigen::Map<const Pair>(xd + i);
    const Pair yi = bx + Eigen::Map<const Pair>(s0d + i);
    Eigen::Map<Pair>(s0d + i) = ((bx + bx) - c.a1 * yi) + Eigen::Map<const Pair>(s1d + i);
    Eigen::Map<Pair>(s1d + i) = bx - c.a2 * yi;
    Eigen::Map<Pair>(yd + i) = yi;
  }
  const double bx = c.b0 * xd[20];  // the odd one out, the same operations
  const double yi = bx + s0d[20];
  s0d[20] = ((bx + bx) - c.a1 * yi) + s1d[20];
  s1d[20] = bx - c.a2 * yi;
  yd[20] = yi;
}

/// One Kalman measurement update of the bias filter (state: the bias, the gyro's scale, the
/// accelerometer's skew; covariance st.cov, symmetric): M independent measurements z = h x +
/// noise, each of variance w, innov = z - h x. Corrects the three and updates the covariance.
/// Written out: P H^T (5xM), S = H P H^T + w I (MxM, symmetric), K = P H^T S^-1, and
/// P -= K (P H^T)^T formed on its upper triangle and mirrored, so P stays exactly symmetric (the
/// full product kept that to rounding only). As Eigen products GCC left them out-of-line calls per
/// SIMD packet: the motion update's step alone cost 102 instructions more per update on the 25 Hz
/// dinghy (callgrind, attitude_count). Always inlined: it runs on every sample, and M fixes the
/// loops.
template <int M>
[[gnu::always_inline]] inline void kalman_update(TelltaleAttitudeFilter::State& st,
                                                 const Eigen::Matrix<double, M, 5>& h,
                                                 const Eigen::Matrix<double, M, 1>& innov,
                                                 double w) {
  Eigen::Matrix<double, 5, 5>& p = st.cov;
  Eigen::Matrix<double, 5, M> pht;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < M; ++j) {
      pht(i, j) = p(i, 0) * h(j, 0) + p(i, 1) * h(j, 1) + p(i, 2) * h(j, 2) + p(i, 3) * h(j, 3) +
                  p(i, 4) * h(j, 4);
    }
  }
  Eigen::Matrix<double, M, M> sm;
  for (int a = 0; a < M; ++a) {
    for (int b = a; b < M; ++b) {
      sm(a, b) = h(a, 0) * pht(0, b) + h(a, 1) * pht(1, b) + h(a, 2) * pht(2, b) +
                 h(a, 3) * pht(3, b) + h(a, 4) * pht(4, b);
      sm(b, a) = sm(a, b);
    }
    sm(a, a) += w;
  }
  const Eigen::Matrix<double, M, M> s_inv = sm.inverse();  // closed form for M <= 3
  Eigen::Matrix<double, 5, M> k;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < M; ++j) {
      double v = 0.0;
      for (int m = 0; m < M; ++m) v += pht(i, m) * s_inv(m, j);
      k(i, j) = v;
    }
  }
  Eigen::Matrix<double, 5, 1> dx;
  for (int i = 0; i < 5; ++i) {
    double v = 0.0;
    for (int m = 0; m < M; ++m) v += k(i, m) * innov(m);
    dx(i) = v;
  }
  for (int i = 0; i < 5; ++i) {
    for (int j = i; j < 5; ++j) {
      double v = 0.0;
      for (int m = 0; m < M; ++m) v += k(i, m) * pht(j, m);
      p(i, j) -= v;
      p(j, i) = p(i, j);
    }
  }
  st.bias_rad_s += dx.head<3>();
  st.gyro_scale += dx(3);
  st.acc_skew_s += dx(4);
}

/// The end of the start's Kalman filter: the low-pass in its steady state (b0, a2: its
/// Butterworth's coefficients for this step) at the start's vertical (|lp| = g: only its
/// direction is read), the rotation and R * bias as they are now, the rate in I at its mean over
/// a seaway (0: the hull's rolling and pitching go both ways); the drift is measured from here.
/// Once per start: not inlined into the update.
[[gnu::noinline]] void end_start_fit(TelltaleAttitudeFilter::State& st, const Eigen::Matrix3d& r,
                                     double b0, double a2, double tau, double g) {
  st.start_fit = false;
  st.lp.col(0) = g * st.up_i;
  st.lp.block<3, 3>(0, 1) = r;
  st.lp.col(4) = r.lazyProduct(st.bias_rad_s);
  st.lp.col(5).setZero();
  st.lp.col(6).setZero();  // R (f x omega) likewise: a seaway's rotations go both ways
  st.lp_s0 = (1.0 - b0) * st.lp;
  st.lp_s1 = (b0 - a2) * st.lp;
  st.lp_running = true;
  st.lp_elapsed_s = tau;
  st.bias_up_i = st.up_i;
  st.bias_skew_lp = st.lp.col(6);
  st.bias_elapsed_s = 0.0;
}

}  // namespace

TelltaleAttitudeParams with_ranges(TelltaleAttitudeParams p, const SensorRanges& ranges) {
  if (std::isfinite(ranges.gyro_rad_s) && ranges.gyro_rad_s > 0.0)
    p.gyro_range_rad_s = ranges.gyro_rad_s;
  if (std::isfinite(ranges.acc_m_s2) && ranges.acc_m_s2 > 0.0) p.acc_range_m_s2 = ranges.acc_m_s2;
  return p;
}

TelltaleAttitudeParams without_ranges(TelltaleAttitudeParams p) {
  p.gyro_range_rad_s = std::numeric_limits<double>::infinity();
  p.acc_range_m_s2 = std::numeric_limits<double>::infinity();
  return p;
}

TelltaleAttitudeFilter::TelltaleAttitudeFilter(Params params)
    : params_(params),
      gate_{params.gyro_range_rad_s, params.acc_range_m_s2, params.saturation_fraction,
            params.max_gap_s, true},
      lever_((params.lever_arm_m.array() != 0.0).any()),
      inv_sqrt2_tau_motion_(M_SQRT1_2 / params.tau_acc_s),
      inv_sqrt2_tau_rest_(M_SQRT1_2 / std::min(params.tau_acc_rest_s, params.tau_acc_s)) {}

void TelltaleAttitudeFilter::initialise(const ImuSample& s) {
  // Frame I starts level-consistent with the first accelerometer sample (yaw 0):
  // q = Ry(-pitch) Rx(heel). Only its vertical matters, and starting it near I's z keeps the
  // horizontal basis of the motion-bias update well away from its switch.
  double heel = 0.0;
  double pitch = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel, pitch);
  const State kept = state_;  // the inputs held across a restart: the clock and the speed
  state_ = State{};
  state_.last_t_s = kept.last_t_s;
  state_.speed_m_s = kept.speed_m_s;
  state_.speed_rate_m_s2 = kept.speed_rate_m_s2;
  state_.yaw_rate_cog_rad_s = kept.yaw_rate_cog_rad_s;
  state_.q_gyro = Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(heel, Eigen::Vector3d::UnitX());
  const Eigen::Matrix3d r = state_.q_gyro.toRotationMatrix();
  state_.lp.col(0) = r * s.acc_body_m_s2;
  state_.lp.block<3, 3>(0, 1) = r;
  state_.lp.col(5) = r * s.gyro_body_rad_s;
  const double n = state_.lp.col(0).norm();
  state_.up_i = n > 0.0 ? Eigen::Vector3d(state_.lp.col(0) / n) : Eigen::Vector3d::UnitZ();
  const double var0 = params_.bias_sigma_init_rad_s * params_.bias_sigma_init_rad_s;
  state_.cov.topLeftCorner<3, 3>() = var0 * Eigen::Matrix3d::Identity();
  state_.cov(3, 3) = params_.gyro_scale_sigma_init * params_.gyro_scale_sigma_init;
  state_.cov(4, 4) = params_.acc_skew_sigma_init_s * params_.acc_skew_sigma_init_s;
  if (have_warm_) {
    // A restart: the sensor as it was learnt (warm_start grew the covariance by its age).
    state_.bias_rad_s = warm_.bias_rad_s;
    state_.gyro_scale = warm_.gyro_scale;
    state_.acc_skew_s = warm_.acc_skew_s;
    state_.cov = warm_.cov;
  }
  // The time constant's scale for the bias as well known as it is (update says why): its
  // sigma (after a restart the root of its three axes' mean variance) against
  // bias_sigma_motion.
  const double sigma_b = have_warm_ ? std::sqrt(state_.cov.topLeftCorner<3, 3>().trace() / 3.0)
                                    : params_.bias_sigma_init_rad_s;
  state_.tau_scale = std::max(1.0, std::cbrt(sigma_b / params_.bias_sigma_motion_rad_s));
  state_.gyro_rest_lp_rad_s = s.gyro_body_rad_s;
  state_.lever_gyro_prev_rad_s = s.gyro_body_rad_s;
  state_.acc_rest_lp_m_s2 = s.acc_body_m_s2;
  state_.initialised = true;
  state_.up_body = r.transpose() * state_.up_i;
  // The start's line fit waits for evidence that the sensor is on a hull under way (update).
  state_.start_pending = params_.start_fit_s > 0.0;
}

void TelltaleAttitudeFilter::start_wait(bool at_rest, bool gap, double dt) {
  State& st = state_;
  st.start_elapsed_s += dt;  // since the first sample, while waiting
  if (at_rest || st.start_elapsed_s >= params_.start_fit_s) {
    st.start_pending = false;
    return;
  }
  if (gap || !(st.speed_m_s > params_.rest_max_speed_m_s)) return;
  // The GNSS speed says the sensor is under way: the start is a hull's in a seaway, and the
  // growing mean the filter began with is the wrong model there (its first values are single
  // samples, one wave's acceleration, and the drift between them was read as a bias of several
  // deg/s and believed). So the line fit starts now, from the vertical and the bias as they are
  // (any linearisation point will do: the fit bends its line about the estimate), with the
  // priors of a first sample: the tilt known to the acceleration a boat can have
  // (start_acc_sigma / g per horizontal axis), the bias to its spread (what the drift learnt
  // under way is worth nothing), uncorrelated; the acceleration's variance starts at the same
  // prior. Its window starts now too, not at the first sample: the line's slope needs
  // start_fit_s of sea (two periods of the slowest wave) whenever the receiver's first fix
  // comes, and a fix a few seconds late (a receiver's cold start) would otherwise leave it one
  // wave's half swing. The cost is the start ending that much later, at most start_fit_s.
  // (After a restart the bias is known as the calibration it began from says: warm_'s
  // covariance.)
  const double a0 = params_.start_acc_sigma_m_s2 / params_.g_m_s2;
  const double var0 = params_.bias_sigma_init_rad_s * params_.bias_sigma_init_rad_s;
  st.start_pending = false;
  st.start_fit = true;
  st.start_elapsed_s = 0.0;
  st.cov.topLeftCorner<3, 3>() = have_warm_ ? Eigen::Matrix3d(warm_.cov.topLeftCorner<3, 3>())
                                            : Eigen::Matrix3d(var0 * Eigen::Matrix3d::Identity());
  // The start's filter has no scale or skew: nothing ties them to the bias.
  st.cov.topRightCorner<3, 2>().setZero();
  st.cov.bottomLeftCorner<2, 3>().setZero();
  st.start_cov.setZero();
  st.start_cov(0, 0) = st.start_cov(1, 1) = a0 * a0;
  st.start_cov.block<3, 3>(2, 2) = st.cov.topLeftCorner<3, 3>();
  st.start_acc_var = a0 * a0;
}

void TelltaleAttitudeFilter::start_fit_update(const Eigen::Matrix3d& r, const Eigen::Vector3d& f,
                                              double dt) {
  // A node started under way has seen no rest: the bias is unknown to +-10 deg/s and the
  // specific force carries the waves' acceleration. The low-pass and its drift (below) cannot
  // start there: the growing mean's first values are single samples (one wave's acceleration,
  // several degrees), and learning the bias from how fast they move reads that wave as a bias
  // of several deg/s, believed at once. What explains the first seconds instead is a line: with
  // a bias error e, frame I turns at R e, so the true vertical in I moves as
  //   d(up)/dt = (R e) x up,
  // and the specific force in I is g up + the boat's acceleration. The least-squares line
  // through it (intercept: the tilt, slope: the bias) is this Kalman filter on 5 states
  // without process noise on the tilt: x = (t1, t2, e), up_true = up_i + t1 h1 + t2 h2 for a
  // horizontal basis h1, h2 = up x h1, so dt1/dt = h2 . (R e), dt2/dt = -h1 . (R e); the
  // measurement is the horizontal specific force (h1, h2) . R f / g = (t1, t2) + a / g. The
  // acceleration is measured as it goes (its variance per axis, a growing mean from the prior)
  // and counted as one measurement per wave_corr_s, not per sample. The state is applied after
  // every sample (up_i tilted, the bias corrected) and reset to 0: the linearisation stays
  // about the estimate, however large the bias was at the start (the line bends with it).
  const Params& p = params_;
  State& st = state_;
  st.start_elapsed_s += dt;
  const Eigen::Vector3d u = st.up_i;
  const Eigen::Vector3d h1 = perpendicular(u);
  const Eigen::Vector3d h2 = u.cross(h1);
  Eigen::Matrix<double, 5, 5> fm = Eigen::Matrix<double, 5, 5>::Identity();
  fm.block<1, 3>(0, 2) = dt * (h2.transpose() * r);
  fm.block<1, 3>(1, 2) = -dt * (h1.transpose() * r);
  Eigen::Matrix<double, 5, 5>& pc = st.start_cov;
  pc = fm * pc * fm.transpose();
  // The bias's own walk, as in the bias filter below.
  const double sm2 = p.bias_sigma_motion_rad_s * p.bias_sigma_motion_rad_s;
  for (int i = 2; i < 5; ++i) pc(i, i) += sm2 * dt / p.bias_forgetting_s;
  const Eigen::Vector3d f_i = r.lazyProduct(f);
  const Eigen::Vector2d z(h1.dot(f_i) / p.g_m_s2, h2.dot(f_i) / p.g_m_s2);
  st.start_acc_var +=
      (0.5 * z.squaredNorm() - st.start_acc_var) * (dt / (st.start_elapsed_s + p.wave_corr_s));
  const double w = st.start_acc_var * p.wave_corr_s / dt;
  Eigen::Matrix2d sm = pc.block<2, 2>(0, 0);
  sm(0, 0) += w;
  sm(1, 1) += w;
  const Eigen::Matrix<double, 5, 2> k = pc.block<5, 2>(0, 0) * sm.inverse();
  const Eigen::Matrix<double, 5, 1> dx = k * z;
  pc -= k * pc.block<2, 5>(0, 0);
  st.up_i = (u + dx(0) * h1 + dx(1) * h2).normalized();
  st.bias_rad_s += dx.tail<3>();
  st.cov.topLeftCorner<3, 3>() = pc.block<3, 3>(2, 2);
}

void TelltaleAttitudeFilter::course_update(const Eigen::Vector3d& gyro_raw, bool usable,
                                           double dt) {
  // The bias about the vertical moves nothing the accelerometer sees, so no rest-less update
  // above learns it; a start under way knows it only to bias_sigma_init. It matters when the
  // boat heels the other way or turns: a tack tilts the body's axes through the vertical, and
  // the bias about the old vertical becomes one about a horizontal axis (5 deg/s of it tilts
  // the vertical by ~2 deg/s for the seconds the low-pass needs). The GNSS course measures
  // it: over a window the gyro's turn about the vertical, minus the bias, is the boat's turn,
  // and so is the course's: (gyro turn - course turn) / T - u . b = u . (b_true - b). Windows
  // of tau_acc_s, the window over which cog_rate_sigma is the course rate's error (leeway,
  // yaw in the waves, the receiver's noise); never while the course is unknown (slow, no
  // fix) or the bow points up or down (its direction means nothing).
  State& st = state_;
  const Params& p = params_;
  if (!usable) {
    st.course_window_s = 0.0;
    st.course_gyro_rad = 0.0;
    st.course_turn_rad = 0.0;
    st.course_up_s.setZero();
    return;
  }
  const Eigen::Vector3d& u = st.up_body;
  st.course_window_s += dt;
  st.course_gyro_rad += gyro_raw.dot(u) * dt;
  st.course_turn_rad += st.yaw_rate_cog_rad_s * dt;
  st.course_up_s += u * dt;
  if (st.course_window_s < p.tau_acc_s) return;
  const double span = st.course_window_s;
  const Eigen::Vector3d hb = st.course_up_s / span;
  // (The gyro's turn is compared unscaled: the scale's share of a tack's 90 deg in 3 s, 0.5 %,
  // is 0.15 deg/s, under the course rate's error.)
  const double innov = (st.course_gyro_rad - st.course_turn_rad) / span - hb.dot(st.bias_rad_s);
  const double w = p.cog_rate_sigma_rad_s * p.cog_rate_sigma_rad_s;
  if (st.start_fit) {
    // The same measurement of the start's filter (H = (0, 0, hb)): its tilt moves with the bias
    // it is correlated with.
    const Eigen::Matrix<double, 5, 1> ph = st.start_cov.block<5, 3>(0, 2) * hb;
    const Eigen::Matrix<double, 5, 1> k = ph / (hb.dot(ph.tail<3>()) + w);
    const Eigen::Vector3d h1 = perpendicular(st.up_i);
    const Eigen::Vector3d h2 = st.up_i.cross(h1);
    st.up_i = (st.up_i + innov * (k(0) * h1 + k(1) * h2)).normalized();
    st.bias_rad_s += innov * k.tail<3>();
    st.start_cov -= k * ph.transpose();
    st.cov.topLeftCorner<3, 3>() = st.start_cov.block<3, 3>(2, 2);
  } else {
    // H = (hb, 0, 0) on (bias, scale, skew): the other two move with the bias they are
    // correlated with.
    const Eigen::Matrix<double, 1, 5> h(hb.x(), hb.y(), hb.z(), 0.0, 0.0);
    kalman_update<1>(st, h, Eigen::Matrix<double, 1, 1>(innov), w);
  }
  st.course_window_s = 0.0;
  st.course_gyro_rad = 0.0;
  st.course_turn_rad = 0.0;
  st.course_up_s.setZero();
}

void TelltaleAttitudeFilter::set_speed(double speed_m_s, double speed_rate_m_s2,
                                       double cog_rate_rad_s) {
  // Filters never throw: anything but a finite speed >= 0 is "unknown", a speed rate that is
  // not finite is 0, a course rate that is not finite is unknown.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  state_.speed_m_s =
      speed_m_s >= 0.0 && speed_m_s < std::numeric_limits<double>::infinity() ? speed_m_s : kNaN;
  state_.speed_rate_m_s2 = std::isfinite(speed_rate_m_s2) ? speed_rate_m_s2 : 0.0;
  // The course turns clockwise (compass), the frame's yaw counter-clockwise.
  state_.yaw_rate_cog_rad_s = std::isfinite(cog_rate_rad_s) ? -cog_rate_rad_s : kNaN;
}

TelltaleCalibration TelltaleAttitudeFilter::calibration() const {
  return {state_.bias_rad_s, state_.gyro_scale, state_.acc_skew_s, state_.cov};
}

bool TelltaleAttitudeFilter::warm_start(const TelltaleCalibration& c, double age_s) {
  const Params& p = params_;
  const bool plausible =
      c.bias_rad_s.allFinite() && c.cov.allFinite() && std::isfinite(c.gyro_scale) &&
      std::isfinite(c.acc_skew_s) && std::isfinite(age_s) && age_s >= 0.0 &&
      c.bias_rad_s.cwiseAbs().maxCoeff() <= p.max_bias_rad_s &&
      std::abs(c.gyro_scale) <= p.max_gyro_scale && std::abs(c.acc_skew_s) <= p.max_acc_skew_s &&
      (c.cov.diagonal().array() >= 0.0).all();
  if (!plausible) return false;
  // A covariance: symmetric, and no combination of the states with a negative variance (its
  // smallest eigenvalue not below the rounding of its largest). Once per start.
  const Eigen::Matrix<double, 5, 5> sym = 0.5 * (c.cov + c.cov.transpose());
  const double scale = sym.cwiseAbs().maxCoeff();
  if ((sym - c.cov).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> eig(sym, Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success || eig.eigenvalues().minCoeff() < -1e-12 * scale) return false;
  // The same walks as the prediction in update(), over the time the node was off: a variance
  // below its prior grows by its rate times age_s; one that reaches the prior is the prior,
  // and its correlations go (what was learnt of it is forgotten).
  const double sm2 = p.bias_sigma_motion_rad_s * p.bias_sigma_motion_rad_s;
  const double b0 = p.bias_sigma_init_rad_s * p.bias_sigma_init_rad_s;
  const double k0 = p.gyro_scale_sigma_init * p.gyro_scale_sigma_init;
  const double s0 = p.acc_skew_sigma_init_s * p.acc_skew_sigma_init_s;
  const std::array<double, 5> prior{b0, b0, b0, k0, s0};
  const std::array<double, 5> rate{sm2 / p.bias_forgetting_s, sm2 / p.bias_forgetting_s,
                                   sm2 / p.bias_forgetting_s, k0 / p.gyro_scale_forgetting_s,
                                   s0 / p.acc_skew_forgetting_s};
  TelltaleCalibration w = c;
  w.cov = sym;
  for (int i = 0; i < 5; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double v = w.cov(i, i) + rate[k] * age_s;
    if (v < prior[k]) {
      w.cov(i, i) = v;
    } else {
      w.cov.row(i).setZero();
      w.cov.col(i).setZero();
      w.cov(i, i) = prior[k];
    }
  }
  warm_ = w;
  have_warm_ = true;
  return true;
}

AttitudeOutput TelltaleAttitudeFilter::output() const {
  AttitudeOutput o;
  if (!state_.initialised) return o;
  o.valid = true;
  if (!state_.updated) {  // the first sample's tilt, rates, weight and quality 0
    tilt_from_accel(state_.up_body, o.heel_rad, o.pitch_rad);
    return o;
  }
  // The samples describe the motion sensor_delay_s before their time stamp (the sensor's
  // digital low-pass and transfer): carry the vertical forward over that delay with the gyro,
  // d(up_body)/dt = up_body x omega (a world-fixed vector seen from a turning body). |u| grows
  // by O((delay omega)^2) only: one Newton step brings it back to unit length.
  const Eigen::Vector3d& u0 = state_.up_body;
  Eigen::Vector3d u = u0 + params_.sensor_delay_s * u0.cross(state_.rate_rad_s);
  u *= 1.5 - 0.5 * u.squaredNorm();
  output_from_up(state_.rate_rad_s, u, o);
  // Reported weight: the share of the specific force's deviation budget left (1 = steady; 0
  // saturated, acc_dev2 = +Inf). Formed here rather than in update(): two divisions that only a
  // read of the output needs.
  o.acc_weight = 1.0 / (1.0 + state_.acc_dev2 / (params_.rest_acc_m_s2 * params_.rest_acc_m_s2));
  // Quality from a rough tilt variance: a bias error e tilts frame I at e, which the low-pass
  // follows with a lag of tau (ramp response of the Butterworth), so the tilt variance is about
  // (2/3 of the bias covariance's trace) * tau^2; while the low-pass is still a growing mean,
  // add (6 deg)^2 fading with its length.
  const double tau = params_.tau_acc_s;
  double var = (2.0 / 3.0) * state_.cov.topLeftCorner<3, 3>().trace() * tau * tau;
  if (state_.start_fit) {
    var = state_.start_cov(0, 0) + state_.start_cov(1, 1);  // the start's own tilt variance
  } else if (!state_.lp_running) {
    var += 0.01 * std::max(0.0, 1.0 - state_.lp_elapsed_s / tau);
  }
  constexpr double kInvVar0 = 1.0 / 7.6e-5;  // 1 / (0.5 deg)^2
  o.quality = 1.0 / (1.0 + var * kInvVar0);
  return o;
}

Eigen::Vector3d TelltaleAttitudeFilter::lever_arm_force(const Eigen::Vector3d& gyro_raw,
                                                        const Eigen::Vector3d& gyro,
                                                        double dt) const {
  // The sensor's motion relative to the centre (Params::lever_arm_m, r): it moves at omega x r
  // in the body, so its specific force carries d(omega)/dt x r + omega x (omega x r) on top of
  // the centre's. Rigid-body kinematics, true on every platform; only the installation's r is
  // needed. Taken off, the specific force is the centre's, whose own acceleration the speed's
  // model takes off and whose remaining motion (the waves') is what the low-pass averages out.
  // The angular acceleration is the raw gyro's difference over the interval (the bias cancels
  // in it; both samples are interval means, so this is the interval's mean change, as the
  // accelerometer's sample is its mean force, half a sample late: 4 deg of phase at a 0.6 Hz
  // wave at 25 Hz); omega is bias-corrected. Its noise is the gyro's, differenced (at 100 Hz
  // ~0.5 m/s^2 per sample on 1.5 m), white, and the low-pass of a difference telescopes: it
  // leaves ~1e-3 m/s^2. The caller skips a gap (no rate is known in it) and a saturated gyro
  // (its rate is clipped).
  const Eigen::Vector3d& arm = params_.lever_arm_m;
  const Eigen::Vector3d alpha = (gyro_raw - state_.lever_gyro_prev_rad_s) / dt;
  return alpha.cross(arm) + gyro.cross(gyro.cross(arm));
}

void TelltaleAttitudeFilter::update(const ImuSample& s) {
  // --- Should this sample be used? (gating apart from the algebra, STYLE rule 6) ---
  const ImuGateResult g = gate_imu_sample(s, gate_, state_.initialised, state_.last_t_s, diag_);
  if (g.verdict == ImuVerdict::kReject) return;
  if (g.verdict == ImuVerdict::kFirst) {
    initialise(s);
    return;
  }
  const Params& p = params_;
  const double dt = g.dt_s;
  const bool gyro_sat = g.gyro_saturated;
  const bool acc_sat = g.acc_saturated;
  const bool gap = g.gap;
  State& st = state_;

  // --- Strapdown integration in frame I. A MEMS gyro sample is the output of its decimation
  // filter, close to the mean rate over the interval that ends at the sample: integrate it over
  // that interval. Over a gap nothing is known about the rotation: not integrated, and the
  // low-pass restarts below (the old vertical in I means nothing any more).
  // With the two-sample coning term (coned_rotation_vector says why): BROAD resampled to
  // 25 Hz, mean inclination error 1.69 -> 1.35 deg; at 100 Hz and above a few hundredths.
  const Eigen::Vector3d gyro_less_bias = s.gyro_body_rad_s - st.bias_rad_s;
  const Eigen::Vector3d gyro = (1.0 + st.gyro_scale) * gyro_less_bias;
  const Eigen::Vector3d dtheta = gyro * dt;
  if (!gap) {
    st.q_gyro = rotate_by(st.q_gyro, coned_rotation_vector(st.dtheta_prev_rad, dtheta));
    st.dtheta_prev_rad = dtheta;
  } else {
    st.dtheta_prev_rad.setZero();  // nothing is known of the rotation over a gap
  }
  const Eigen::Matrix3d r = st.q_gyro.toRotationMatrix();  // body -> I

  // --- Rest detection. Rest = both sensors steady about their own 0.5 s means (a knock, a
  // vibration or any rotation that changes moves one of them), AND the gyro's mean is a value
  // the bias can take: within 3 sigma of the estimate per axis, floored at rest_bias_gate. A
  // constant rotation about the vertical keeps both sensors steady (the accelerometer reads the
  // same tilt all the time), so only the bias test tells it from a rest. And a boat the GNSS
  // sees making way is not at rest: a swell rolls and pitches it slowly enough (0.3 Hz, a few
  // deg/s) to pass the 0.5 s steadiness tests, and the gyro's mean there is the swell's rate,
  // not the bias (read as a bias measured to 0.03 deg/s, it tilted a start under way by 10 deg).
  const double a_rest = std::min(1.0, dt / p.rest_lp_tau_s);
  st.gyro_rest_lp_rad_s += a_rest * (s.gyro_body_rad_s - st.gyro_rest_lp_rad_s);
  st.acc_rest_lp_m_s2 += a_rest * (s.acc_body_m_s2 - st.acc_rest_lp_m_s2);
  const double acc_dev2 = (s.acc_body_m_s2 - st.acc_rest_lp_m_s2).squaredNorm();
  // (The bias gate, 3 sigma per axis floored at rest_bias_gate, is formed inside the test, so
  // only for a sample that passed the steadiness tests before it: in motion it is never formed.
  // The same comparisons on the same values; 20 instructions per update on the dinghy.)
  const bool steady = !gyro_sat && !acc_sat && !gap &&
                      (s.gyro_body_rad_s - st.gyro_rest_lp_rad_s).squaredNorm() <
                          p.rest_gyro_rad_s * p.rest_gyro_rad_s &&
                      acc_dev2 < p.rest_acc_m_s2 * p.rest_acc_m_s2 &&
                      ((st.gyro_rest_lp_rad_s - st.bias_rad_s).array().square() <
                       (9.0 * st.cov.diagonal().head<3>())
                           .cwiseMax(p.rest_bias_gate_rad_s * p.rest_bias_gate_rad_s)
                           .array())
                          .all() &&
                      !(st.speed_m_s > p.rest_max_speed_m_s);
  st.rest_time_s = steady ? st.rest_time_s + dt : 0.0;
  const bool at_rest = st.rest_time_s >= p.rest_min_s;
  // The reported weight's input (output() forms the weight; 1 / (1 + Inf) is the 0 of a
  // saturated sample).
  st.acc_dev2 = acc_sat ? std::numeric_limits<double>::infinity() : acc_dev2;

  // --- Low-pass in frame I: the specific force, and the rotation matrix and R * bias that the
  // motion-bias model needs filtered the same way. A saturated sample is fed as it is: it is
  // still the best bound on the acceleration, and leaving the strongest samples out would bias
  // the mean toward the other side (a shake's hard stops and gentle starts would leave a tilt).
  Eigen::Vector3d f = s.acc_body_m_s2;
  // A sensor off the boat's centre (Params::lever_arm_m): its own swing about the centre taken
  // off first (lever_arm_force), so that what is left is the centre's specific force, which the
  // speed's model below describes. It is that model's other half, and runs only with it (the
  // speed known): the sensor's acceleration is the centre's plus its swing, and taking off the
  // swing alone leaves a tack's centre acceleration (v x turn rate, 1-2 m/s^2 for 2-4 s) whole,
  // where the bow's swing had happened to offset part of it in pitch (dinghy without GNSS,
  // 30 seeds, 25 Hz: pitch 0.65 -> 0.72 deg RMS, 2.15 -> 2.50 max, heel 1.01 -> 0.91,
  // 3.85 -> 3.38). So an unknown speed still leaves the filter exactly as without it. Not over a
  // gap nor with the gyro saturated.
  if (lever_) {
    if (!gap && !gyro_sat && st.speed_m_s >= 0.0) f -= lever_arm_force(s.gyro_body_rad_s, gyro, dt);
    st.lever_gyro_prev_rad_s = s.gyro_body_rad_s;
  }
  if (st.speed_m_s >= 0.0) {
    // The boat's own acceleration, taken off the specific force when its speed is known. Its
    // velocity is horizontal along the bow's horizontal direction hb = (e_x - u_x u) / |.| (u:
    // the vertical in the body, from the last update); the velocity turns with the yaw rate
    // about the vertical, w_up = omega . u, so a = (dv/dt) hb + v w_up (u x hb), and
    // u x e_x = (0, u_z, -u_y). Pitching and rolling do not turn a horizontal velocity: only
    // w_up enters (the body-frame omega x (v, 0, 0) would also count the bow's pitching as a
    // vertical acceleration of the whole boat). In a tack (0.8 rad/s at 1.5 m/s) this is
    // 1.2 m/s^2 to one side for 2-4 s: 7 deg of false heel that the low-pass cannot average.
    const Eigen::Vector3d& u = st.up_body;
    const double n2 = 1.0 - u.x() * u.x();
    if (n2 > 0.25) {  // the bow within 60 deg of horizontal (else its direction means nothing)
      const double inv_n = 1.0 / std::sqrt(n2);
      double w_up = gyro.dot(u);
      if (!std::isnan(st.yaw_rate_cog_rad_s)) {
        // The gyro's error about the vertical is its bias there (variance u^T P u); the course
        // rate's is cog_rate_sigma. Their variance-weighted mean (the Kalman update of one
        // measurement of the other).
        const double vg = u.dot(st.cov.topLeftCorner<3, 3>() * u);
        const double vc = p.cog_rate_sigma_rad_s * p.cog_rate_sigma_rad_s;
        w_up += vg / (vg + vc) * (st.yaw_rate_cog_rad_s - w_up);
      }
      const double turn = st.speed_m_s * w_up;
      const double along = st.speed_rate_m_s2;
      const Eigen::Vector3d a_body(along * (1.0 - u.x() * u.x()),
                                   -along * u.x() * u.y() + turn * u.z(),
                                   -along * u.x() * u.z() - turn * u.y());
      f -= inv_n * a_body;
    }
  }
  // --- The specific force, so far in the body at the sample's own instant, seen from r: turned
  // back by half the interval's rotation (force_at_its_instant says why), for the start's line
  // fit and the low-pass alike: BROAD resampled to 25 Hz, with the coning term, mean
  // inclination error 1.35 -> 0.98 deg (docs/attitude.md has every rate).
  // The accelerometer's own skew (Params::acc_skew_sigma_init_s, a state): its sample describes
  // the instant acc_skew_s before the gyro's, a further turn of omega * acc_skew_s.
  const Eigen::Vector3d f_seen =
      gap ? f : force_at_its_instant(f, dtheta + (2.0 * st.acc_skew_s) * gyro);
  // The course measures the bias about the vertical when it is known (course_update).
  const bool course_known = !gap && st.speed_m_s >= 0.0 &&
                            !std::isnan(st.yaw_rate_cog_rad_s) &&
                            1.0 - st.up_body.x() * st.up_body.x() > 0.25;
  // --- The start. Every filter begins with the growing mean below. The line fit
  // (start_fit_update) models a hull in a seaway, and it is that which decides whether it may
  // run: only a GNSS speed above rest_max_speed (the platform making way; the same evidence that
  // vetoes a rest) within start_fit_s of the first sample engages it. Not the speed at the first
  // sample: a receiver's first fix comes after the IMU's first samples. A handled phone turns
  // through hundreds of degrees in its first seconds and the fit would take that for a bias;
  // a phone or a bench has no GNSS, and never enters it. A rest ends the wait (it measures the
  // bias far better, and a platform at rest is in no seaway); a gap does not (the fit starts
  // from the estimate whenever it starts), but the fit never starts at one.
  if (st.start_pending) start_wait(at_rest, gap, dt);
  // The fit runs until start_fit_s have passed since it began, or a rest or a gap comes first
  // (a rest measures the bias far better; over a gap the line breaks). Then the low-pass takes
  // over below, in its steady state at the start's vertical, with its bias covariance.
  const bool start_ends = st.start_fit && (at_rest || gap || st.start_elapsed_s >= p.start_fit_s);
  if (st.start_fit && !start_ends) {
    start_fit_update(r, f_seen, dt);
    if (course_known || st.course_window_s > 0.0)
      course_update(s.gyro_body_rad_s, course_known, dt);
    st.bias_rad_s = st.bias_rad_s.cwiseMax(-p.max_bias_rad_s).cwiseMin(p.max_bias_rad_s);
    st.up_body = r.transpose() * st.up_i;
    st.rate_rad_s = gyro;
    st.updated = true;
    return;
  }

  // The time constant trades the gyro against the accelerometer. Over tau a horizontal bias
  // error sigma_b tilts frame I by sigma_b * tau, while an oscillating acceleration A at
  // frequency w leaks through the 2nd-order low-pass as A / (g (w tau)^2): the sum is smallest
  // at tau^3 = 2 A / (g w^2 sigma_b). tau_acc_s is that optimum once the bias is known to
  // bias_sigma_motion; with the bias known less well (a start under way, before any rest) the
  // gyro is worth less and tau = tau_acc_s (sigma_motion / sigma_b)^(1/3), never longer than
  // tau_acc_s. sigma_b^2: the covariance's mean over the two axes across the vertical. The cube
  // root by one Newton step per sample from the last value (it changes slowly).
  // (A lazy product, here and for up_body: as `*` GCC made it an out-of-line call, 50
  // instructions per update.)
  const Eigen::Vector3d up_b_prev = r.transpose().lazyProduct(st.up_i);
  const double sm2 = p.bias_sigma_motion_rad_s * p.bias_sigma_motion_rad_s;
  const auto bias_cov = st.cov.topLeftCorner<3, 3>();
  const double var_h = 0.5 * (bias_cov.trace() - up_b_prev.dot(bias_cov * up_b_prev));
  // At rest there is no acceleration to average out (that is what rest means): the low-pass may
  // follow the accelerometer faster and wipe out the tilt error the motion left behind.
  // The bias known to sigma_m or better (the usual case once the filter has settled: 98 % of the
  // dinghy's updates keep tau_scale at 1) needs no root: max(1, sqrt(var_h / sm2)) is 1 (NaN
  // included, as std::max(1, NaN) is 1) and Newton's step from z = 1 gives (2 + 1) * (1 / 3) = 1
  // exactly (3 times the double nearest 1/3 rounds to 1). Skipping it gives the same z, bit for
  // bit, without a square root and two divisions.
  // (With z = 1 tau_acc_s / z is tau_acc_s and M_SQRT1_2 / tau the constructor's: the same
  // bits without the two divisions, which lie on the chain from dt to the low-pass.)
  double tau_motion = p.tau_acc_s;
  bool scaled = false;
  if (var_h > sm2 || st.tau_scale != 1.0 || start_ends) {
    // x = (var_h / sigma_m^2)^(1/2) -> tau = tau_acc_s / cbrt(max(1, x)); Newton on z^3 = x.
    const double ratio = std::max(1.0, std::sqrt(var_h / sm2));
    // (At the start's end the covariance has jumped since the last step: the root itself.)
    double z = start_ends ? std::cbrt(ratio) : st.tau_scale;
    z = (2.0 * z + ratio / (z * z)) * (1.0 / 3.0);
    st.tau_scale = z;
    tau_motion = p.tau_acc_s / z;
    scaled = true;
  }
  const double tau = at_rest ? std::min(p.tau_acc_rest_s, tau_motion) : tau_motion;
  const double inv_sqrt2_tau =
      scaled ? M_SQRT1_2 / tau : (at_rest ? inv_sqrt2_tau_rest_ : inv_sqrt2_tau_motion_);
  const Butterworth c = butterworth(dt, inv_sqrt2_tau);
  if (start_ends) end_start_fit(st, r, c.b0, c.a2, tau, p.g_m_s2);
  if (gap) st.lp_running = false;
  Eigen::Matrix<double, 3, 7> x;
  // (Written out: as Eigen assignments GCC left the block copy and the products out-of-line
  // calls once the update had grown by the lines above, +55 instructions per update.)
  const Eigen::Vector3d& b = st.bias_rad_s;
  const Eigen::Vector3d& wb = gyro_less_bias;
  const Eigen::Vector3d fw = f_seen.cross(gyro);  // how a late force tilts (the skew's column)
  for (int i = 0; i < 3; ++i) {
    x(i, 0) = r(i, 0) * f_seen.x() + r(i, 1) * f_seen.y() + r(i, 2) * f_seen.z();
    x(i, 1) = r(i, 0);
    x(i, 2) = r(i, 1);
    x(i, 3) = r(i, 2);
    x(i, 4) = r(i, 0) * b.x() + r(i, 1) * b.y() + r(i, 2) * b.z();
    x(i, 5) = r(i, 0) * wb.x() + r(i, 1) * wb.y() + r(i, 2) * wb.z();
    x(i, 6) = r(i, 0) * fw.x() + r(i, 1) * fw.y() + r(i, 2) * fw.z();
  }
  if (!st.lp_running) {
    // Fast start: the mean of everything since the (re)start, weighted by time. The first
    // sample after a restart replaces the mean. Once tau has been covered, the Butterworth takes
    // over in its steady state at that mean.
    const double elapsed = gap ? 0.0 : st.lp_elapsed_s + dt;
    const double w = gap ? 1.0 : dt / elapsed;
    st.lp += w * (x - st.lp);
    st.lp_elapsed_s = elapsed;
    if (elapsed >= tau) {
      st.lp_running = true;
      st.lp_s0 = (1.0 - c.b0) * st.lp;
      st.lp_s1 = (c.b0 - c.a2) * st.lp;
    }
  } else {
    butterworth_step(c, x, st.lp, st.lp_s0, st.lp_s1);
  }

  // --- Inclination correction: the vertical of frame I is the direction of the low-passed
  // specific force (the correction that maps it to "up").
  const double l2 = st.lp.col(0).squaredNorm();
  if (l2 > 0.25 * p.g_m_s2 * p.g_m_s2) st.up_i = st.lp.col(0) / std::sqrt(l2);

  // --- Gyro bias, a Kalman filter on 3 states. Prediction: a random walk that lets the bias
  // be forgotten over bias_forgetting_s (capped at the initial uncertainty).
  const double v = sm2 * dt / p.bias_forgetting_s;
  const double var0 = p.bias_sigma_init_rad_s * p.bias_sigma_init_rad_s;
  for (int i = 0; i < 3; ++i) {
    if (st.cov(i, i) < var0) st.cov(i, i) += v;
  }
  // The scale's walk: back to its prior over gyro_scale_forgetting_s.
  const double ks0 = p.gyro_scale_sigma_init * p.gyro_scale_sigma_init;
  if (st.cov(3, 3) < ks0) st.cov(3, 3) += ks0 * dt / p.gyro_scale_forgetting_s;
  // The skew's likewise.
  const double ss0 = p.acc_skew_sigma_init_s * p.acc_skew_sigma_init_s;
  if (st.cov(4, 4) < ss0) st.cov(4, 4) += ss0 * dt / p.acc_skew_forgetting_s;
  // Measurement noise chosen so that, updated on every sample, the covariance settles at the
  // sigma of that measurement: W = sigma^4 / V + sigma^2 (the fixed point of P' = P + V,
  // P'' = P' - P'^2 / (P' + W) at P'' = sigma^2).
  if (at_rest) {
    ++diag_.rest_samples;
    // At rest the gyro's 0.5 s mean IS the bias (to its noise), all three axes.
    const double sr2 = p.bias_sigma_rest_rad_s * p.bias_sigma_rest_rad_s;
    const double w = sr2 * sr2 / v + sr2;
    // H = (I, 0, 0) on (bias, scale, skew): the scale and the skew are not measured (no
    // rotation), but move with the bias they are correlated with, and that correlation shrinks
    // as the bias is pinned down.
    Eigen::Matrix<double, 3, 5> h = Eigen::Matrix<double, 3, 5>::Zero();
    h.leftCols<3>().setIdentity();
    const Eigen::Vector3d innov = st.gyro_rest_lp_rad_s - st.bias_rad_s;
    kalman_update<3>(st, h, innov, w);
  }
  // The motion update runs at most every kBiasPeriod_s (the paper's 25 Hz): the bias changes
  // over minutes, and the drift of the vertical over 40 ms is a better-conditioned measurement
  // than over one 3.5 ms step, at a fraction of the cost. Not longer: 0.1 and 0.25 s left BROAD
  // and every simulator row within 0.01 deg (and saved 120-210 instructions per update at
  // 25 Hz), but the phones' up through their handling moved the IPIN walks' loop closures from
  // 5 to 3 and 2 of 8 within 2 % (one live track 4.4 -> 19.9 %; docs/attitude.md, Speed).
  constexpr double kBiasPeriod_s = 0.04;
  // Not while the low-pass is still the growing mean of its start: the drift that measures the
  // bias, scale and skew is the Butterworth's response to them (below), and the growing mean's
  // is another filter's (each sample weighs dt / elapsed, a new sample moves the mean by
  // everything it differs from it). A filter started in motion read that as all three: on BROAD
  // started at each trial's first movement row (the bias known from the rest before, trial 29)
  // it learnt a skew of 16 ms in its first second and unlearnt it over a minute; mean
  // inclination RMSE 2.39 -> 2.00 deg cold, 0.70 -> 0.52 restarted; from rest, where the growing
  // mean runs at rest, every trial the same (docs/attitude.md, "Started in motion"). (Tested
  // last: at the head of the test GCC arranged the update's branches around it, +48
  // instructions per update, callgrind.)
  const bool motion =
      !at_rest && !steady && !gap && !acc_sat && l2 > 0.25 * p.g_m_s2 * p.g_m_s2 && st.lp_running;
  if (!motion) {
    st.bias_up_i = st.up_i;
    st.bias_skew_lp = st.lp.col(6);
    st.bias_elapsed_s = 0.0;
  } else {
    st.bias_elapsed_s += dt;
  }
  if (motion && st.bias_elapsed_s >= kBiasPeriod_s) {
    // (Not while the sensors are steady: that may be the start of a rest, which measures the
    // bias far better; learning from the slow drift there first would shrink the covariance and
    // shut the rest gate on the true bias.)
    // In motion: a residual bias e rotates gravity in I at R e (d g_I / dt = (R e) x g_I), so
    // the low-passed vertical turns at y = up_prev x up / dt ~ LP(R e) across the vertical.
    // With the bias estimate b: LP(R) b_true = y + LP(R b), a measurement of the bias through
    // H = LP(R), of its two horizontal components only (the vertical one moves nothing).
    // The scale: the integrated rate is (1 + k)(gyro - b) against the true (1 + k_true)(gyro -
    // b_true), which part by (b_true - b) - (k_true - k)(gyro - b) to first order, so the same
    // drift is also a measurement of k_true - k through -LP(R (gyro - b)), the low-passed rate in
    // I. A rotation that goes back and forth (a boat's rolling, a pendulum) leaves that near 0
    // and teaches nothing; a one-way rotation across the vertical (a hand tumbling the sensor,
    // a turntable's tilted axis) measures it.
    // The skew: the force is turned back by omega s_est beyond the half interval, where its
    // sample asks for omega s_true, so the low-passed force carries
    // (s_est - s_true) LP(R (f x omega)) on top of g up, a tilt of the vertical
    // by that over g (across the vertical), and the vertical's drift over the span carries its
    // change: (s_est - s_true) up x d/dt LP(R (f x omega)) / g. So the same drift measures
    // s_true - s_est through -(up x dLP / dt) / g. A steady rotation holds the tilt and says
    // nothing; its onset, its end and any change of its axis or rate do. It is not the scale's
    // signature (the scale drifts the vertical for as long as the rotation lasts, the skew tilts
    // it once), nor the bias's (which drifts it through R).
    const double span = st.bias_elapsed_s;
    const Eigen::Vector3d yv = st.bias_up_i.cross(st.up_i) / span;
    st.bias_up_i = st.up_i;
    st.bias_elapsed_s = 0.0;
    const Eigen::Matrix3d h_i = st.lp.block<3, 3>(0, 1);
    const Eigen::Vector3d e_i = yv + st.lp.col(4) - h_i * st.bias_rad_s;
    const Eigen::Vector3d h1 = perpendicular(st.up_i);
    const Eigen::Vector3d h2 = st.up_i.cross(h1);
    Eigen::Matrix<double, 2, 3> basis;
    basis.row(0) = h1.transpose();
    basis.row(1) = h2.transpose();
    Eigen::Matrix<double, 2, 5> h;
    h.leftCols<3>() = basis * h_i;
    h.col(3) = -(basis * st.lp.col(5));
    const Eigen::Vector3d skew_lp_rate = (st.lp.col(6) - st.bias_skew_lp) / span;
    h.col(4) = -(basis * st.up_i.cross(skew_lp_rate)) / p.g_m_s2;
    st.bias_skew_lp = st.lp.col(6);
    Eigen::Vector2d e = basis * e_i;
    e = e.cwiseMax(-p.max_bias_rad_s).cwiseMin(p.max_bias_rad_s);
    // The same steady-state rule for one update per span: V over the span.
    const double w = sm2 * p.bias_forgetting_s / span + sm2;
    kalman_update<2>(st, h, e, w);
  }
  if (course_known || st.course_window_s > 0.0) course_update(s.gyro_body_rad_s, course_known, dt);
  st.bias_rad_s = st.bias_rad_s.cwiseMax(-p.max_bias_rad_s).cwiseMin(p.max_bias_rad_s);
  st.gyro_scale = std::clamp(st.gyro_scale, -p.max_gyro_scale, p.max_gyro_scale);
  st.acc_skew_s = std::clamp(st.acc_skew_s, -p.max_acc_skew_s, p.max_acc_skew_s);

  // --- What output() needs: the vertical seen in the body, and the body rate.
  st.up_body = r.transpose().lazyProduct(st.up_i);
  st.rate_rad_s = gyro;
  st.updated = true;
}

}  // namespace telltale::fusion
