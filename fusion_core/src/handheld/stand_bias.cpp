#include "telltale/fusion/handheld/stand_bias.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace telltale::fusion {

double handheld_magnetic_heading(const Eigen::Vector3d& mag, const Eigen::Vector3d& up,
                                 const Eigen::Vector3d& axis) {
  Eigen::Vector3d east = mag.cross(up);
  if (!(east.norm() > 1e-6)) return std::numeric_limits<double>::quiet_NaN();
  east.normalize();
  const Eigen::Vector3d north = up.cross(east);
  const Eigen::Vector3d h = axis - axis.dot(up) * up;
  if (!(h.norm() > 0.1)) return std::numeric_limits<double>::quiet_NaN();
  return std::atan2(h.dot(east), h.dot(north));
}

void StandBiasLearner::clear_window() {
  auto& st = state_;
  st.win_n = 0;
  st.win_a = st.win_a2 = st.win_w2 = 0.0;
  st.win_w.setZero();
  st.win_yaw = {};
  st.win_yaw_ok = true;
}

void StandBiasLearner::update(const ImuSample& s, const Eigen::Vector3d& up,
                              const Eigen::Vector3d& mag_uT) {
  auto& st = state_;
  if (!st.started) {
    st.started = true;
    st.last_t_s = s.t_s;
    st.win_t0_s = s.t_s;
    st.t_origin_s = s.t_s;
    return;
  }
  const double dt = s.t_s - st.last_t_s;
  st.last_t_s = s.t_s;
  if (!(dt > 0.0) || dt > 0.5) {  // a gap: the window and the stand restart
    close_stand();
    clear_window();
    st.win_t0_s = s.t_s;
    st.have_psi_m = false;
    return;
  }
  const double a = s.acc_body_m_s2.norm();
  st.win_a += a;
  st.win_a2 += a * a;
  st.win_w2 += s.gyro_body_rad_s.squaredNorm();
  st.win_w += s.gyro_body_rad_s * dt;
  ++st.win_n;
  // The gyro's and the field's yaw about the vertical (counter-clockwise seen from above).
  st.psi_g += s.gyro_body_rad_s.dot(up) * dt;
  if (params_.mag_yaw_bias) {
    const double h = mag_uT.allFinite() ? handheld_magnetic_heading(mag_uT, up, kHandheldForward)
                                        : std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(h)) {
      const double raw = -h;  // a counter-clockwise turn lowers the heading
      st.psi_m = st.have_psi_m ? st.psi_m + std::remainder(raw - st.psi_m_raw, 2.0 * M_PI) : raw;
      st.psi_m_raw = raw;
      st.have_psi_m = true;
      const double t = s.t_s - st.t_origin_s;
      const double d = st.psi_g - st.psi_m;
      const double b = mag_uT.norm();
      const double bv = mag_uT.dot(up);
      auto& y = st.win_yaw;
      y.n += 1.0;
      y.t += t;
      y.d += d;
      y.tt += t * t;
      y.td += t * d;
      y.dd += d * d;
      y.b += b;
      y.bb += b * b;
      y.bh += std::sqrt(std::max(0.0, b * b - bv * bv));
      y.up += up;
    } else {
      st.win_yaw_ok = false;
      st.have_psi_m = false;  // the next field sample starts a new unwrap (the window is void)
    }
  }
  const double span = s.t_s - st.win_t0_s;
  if (span < params_.window_s) return;
  const double n = static_cast<double>(st.win_n);
  const double mean_a = st.win_a / n;
  const double sd_a = std::sqrt(std::max(0.0, st.win_a2 / n - mean_a * mean_a));
  const double rms_w = std::sqrt(st.win_w2 / n);
  st.quiet = sd_a < params_.max_acc_sd_m_s2 && rms_w < params_.max_gyro_rms_rad_s;
  if (st.quiet) {
    st.stand_s += span;
    st.stand_w_dt += st.win_w;
    st.stand_yaw.add(st.win_yaw);
    st.stand_yaw_ok = st.stand_yaw_ok && st.win_yaw_ok;
  } else {
    close_stand();
  }
  clear_window();
  st.win_t0_s = s.t_s;
  update_estimate();
}

namespace {
/// Least-squares slope of d against t from the sums; NaN if the stand is unfit for it.
double mag_slope(const StandBiasLearner::State::YawSums& y, const StandBiasParams& p) {
  if (y.n < 10.0) return std::numeric_limits<double>::quiet_NaN();
  const double mb = y.b / y.n;
  const double sd_b = std::sqrt(std::max(0.0, y.bb / y.n - mb * mb));
  if (sd_b > p.max_mag_norm_sd_uT || y.bh / y.n < p.min_mag_horizontal_uT)
    return std::numeric_limits<double>::quiet_NaN();
  const double den = y.n * y.tt - y.t * y.t;
  if (!(den > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (y.n * y.td - y.t * y.d) / den;
}

/// How much a stand's magnetic slope counts against the others: the inverse of its variance.
/// d(t) over a stand is a line (the bias) plus what the line does not explain: the magnetic
/// yaw's noise, the hand's tilt wander leaking into the tilt-compensated heading, small bends
/// of the field's direction as the hand moves the phone through indoor gradients. Those wander
/// about the line with some correlation time tau (about a second: the hand's sway), so over a
/// stand of T seconds they give ~T / tau independent samples spread over T, and the
/// least-squares slope's variance is 12 s^2 tau / T^3, s^2 the residual variance about the
/// line. tau is the hand's and the same for every stand, so the weight is T^3 / s^2: a long,
/// clean stand counts far more than a short one or one whose field wandered. (The T^2 of the
/// gyro's stand mean is right for that estimate, whose error is the net rotation / T, but not
/// for a fitted slope.) Measured on the 25 stands of the IPIN walks against the bias their
/// walked legs imply (a line through each leg's heading error): slope errors 0.01-0.48 deg/s,
/// 21 of 25 within 1.5 sigma of sqrt(12 s^2 tau / T^3) with tau = 1 s; the other four are
/// long clean stands (sigma <= 0.035 deg/s, errors 0.09-0.18 deg/s) of route 01, two of them
/// walk 3's, whose bias while walking differs from both of its stands'.
double mag_slope_weight(const StandBiasLearner::State::YawSums& y, double stand_s, double slope) {
  const double s_dd = y.dd - y.d * y.d / y.n;  // sum of (d - mean)^2
  const double s_td = y.td - y.t * y.d / y.n;  // sum of (t - mean)(d - mean)
  // Residual variance about the line; floored at (0.1 deg)^2, below any real magnetometer's
  // heading noise (0.4 uT on a 20 uT horizontal field is 1.1 deg), so that a noiseless
  // simulated stand does not get an infinite weight.
  constexpr double kMinVar = (0.1 * M_PI / 180.0) * (0.1 * M_PI / 180.0);
  const double var = std::max(kMinVar, (s_dd - slope * s_td) / y.n);
  return stand_s * stand_s * stand_s / var;
}
}  // namespace

void StandBiasLearner::update_estimate() {
  auto& st = state_;
  // The gyro estimate: the closed stands and the one in progress, each weighted by T^2.
  double weight = st.done_weight;
  Eigen::Vector3d sum = st.done_sum;
  double mweight = st.mag_weight, msum = st.mag_sum;
  Eigen::Vector3d mup = st.mag_up;
  if (st.stand_s >= params_.min_stand_s) {
    const double w = st.stand_s * st.stand_s;
    const Eigen::Vector3d mean = st.stand_w_dt / st.stand_s;
    if (mean.norm() <= params_.max_bias_rad_s) {
      weight += w;
      sum += w * mean;
    }
    const double slope = st.stand_yaw_ok && params_.mag_yaw_bias
                             ? mag_slope(st.stand_yaw, params_)
                             : std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(slope) && std::fabs(slope) <= params_.max_bias_rad_s &&
        st.stand_yaw.up.norm() > 0.0) {
      const double wm = mag_slope_weight(st.stand_yaw, st.stand_s, slope);
      mweight += wm;
      msum += wm * slope;
      mup += wm * st.stand_yaw.up.normalized();
    }
  }
  if (weight > 0.0) {
    st.bias = sum / weight;
    st.have_bias = true;
  }
  if (mweight > 0.0 && mup.norm() > 0.0) {
    // The component along the stands' vertical from the field; the others from the gyro.
    const Eigen::Vector3d u = mup.normalized();
    st.vertical_bias = msum / mweight;
    st.bias += (st.vertical_bias - st.bias.dot(u)) * u;
    st.have_bias = true;
  }
}

void StandBiasLearner::close_mag_stand() {
  auto& st = state_;
  if (params_.mag_yaw_bias && st.stand_yaw_ok && st.stand_s >= params_.min_stand_s) {
    const double slope = mag_slope(st.stand_yaw, params_);
    if (std::isfinite(slope) && std::fabs(slope) <= params_.max_bias_rad_s &&
        st.stand_yaw.up.norm() > 0.0) {
      const double w = mag_slope_weight(st.stand_yaw, st.stand_s, slope);
      st.mag_weight += w;
      st.mag_sum += w * slope;
      st.mag_up += w * st.stand_yaw.up.normalized();
    }
  }
  st.stand_yaw = {};
  st.stand_yaw_ok = true;
}

void StandBiasLearner::close_stand() {
  auto& st = state_;
  if (st.stand_s >= params_.min_stand_s) {
    const Eigen::Vector3d mean = st.stand_w_dt / st.stand_s;
    if (mean.norm() <= params_.max_bias_rad_s) {
      st.done_weight += st.stand_s * st.stand_s;
      st.done_sum += st.stand_s * st.stand_s * mean;
    }
  }
  close_mag_stand();
  st.stand_s = 0.0;
  st.stand_w_dt.setZero();
  st.quiet = false;
}

}  // namespace telltale::fusion
