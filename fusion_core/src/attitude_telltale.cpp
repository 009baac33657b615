// Telltale's production heel/pitch filter. The contract and the ideas are in the header; here is
// why each step is done the way it is.
#include "telltale/fusion/attitude_telltale.hpp"

#include <algorithm>
#include <cmath>

namespace telltale::fusion {
namespace {

/// q * (quaternion of the rotation vector v (rad)), brought back to unit norm. The rotation's
/// quaternion dq = (c, s v), c = cos(|v|/2), s = sin(|v|/2) / |v|, is accurate to O(|v|^5)
/// without sin/cos: at 25 Hz and 5 rad/s |v| = 0.2 rad and the error is < 1e-6 rad per step.
/// Arranged for a short dependency chain (v depends on the bias the last update refined, and
/// everything in this update depends on q): q dq = c q + s (q (0, v)), where q (0, v) needs only
/// v and is formed while c and s are; c and s are evaluated in Estrin's form, with
/// (|v|/2)^2 = n / 4 folded into the constants (powers of two: exact).
Eigen::Quaterniond rotate_by(const Eigen::Quaterniond& q, const Eigen::Vector3d& v) {
  const double n = v.squaredNorm();
  const double n2 = n * n;
  // c = 1 - a2 / 2 + a2^2 / 24, s = 1 / 2 - a2 / 12 + a2^2 / 240 with a2 = n / 4. Constant
  // reciprocals: the compiler may not turn x / 24 into a multiplication (not exact), and a
  // division is 13-20 cycles on the update's critical path.
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

double clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

}  // namespace

TelltaleAttitudeFilter::TelltaleAttitudeFilter(Params params) : params_(params) {
  const Params& p = params_;
  rates_ = {1.0 / p.rest_lp_tau_s,
            1.0 / p.rest_bias_tau_s,
            1.0 / p.nonin_lp_tau_s,
            1.0 / p.nonin_release_s,
            1.0 / p.turn_tau_s,
            1.0 / p.turn_release_s,
            1.0 / p.tau_acc_s,
            1.0 / p.tau_acc_rest_s,
            1.0 / p.bias_motion_tau_s,
            1.0 / (p.nonin_high_m_s2 - p.nonin_low_m_s2),
            1.0 / (p.turn_high_m_s2 - p.turn_low_m_s2),
            1.0 / p.turn_rate_rad_s,
            p.saturation_fraction * p.gyro_range_rad_s,
            p.saturation_fraction * p.acc_range_m_s2,
            1.0 / p.g_m_s2,
            1.0 / (p.g_m_s2 * p.g_m_s2),
            1.0 + p.nonin_low_m_s2 / (p.nonin_high_m_s2 - p.nonin_low_m_s2),
            1.0 + p.turn_low_m_s2 / (p.turn_high_m_s2 - p.turn_low_m_s2),
            1.5 / p.g_m_s2,
            0.5 / (p.g_m_s2 * p.g_m_s2 * p.g_m_s2)};
}

void TelltaleAttitudeFilter::initialise(const ImuSample& s) {
  // Start level-consistent with the first accelerometer sample (yaw 0): q = Ry(-pitch) Rx(heel).
  double heel = 0.0;
  double pitch = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel, pitch);
  state_ = State{};
  state_.q_gyro = Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(heel, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d acc_i = state_.q_gyro * s.acc_body_m_s2;
  state_.acc_lp1_i = acc_i;
  state_.acc_lp2_i = acc_i;
  state_.acc_fast_i = acc_i;
  state_.gyro_rest_lp_rad_s = s.gyro_body_rad_s;
  state_.acc_rest_lp_m_s2 = s.acc_body_m_s2;
  state_.last_t_s = s.t_s;
  state_.tilt_var_rad2 = 0.01;  // (6 deg)^2: unknown until the first seconds have been seen
  state_.initialised = true;
  state_.up_body = state_.q_gyro.toRotationMatrix().row(2).transpose();  // R^T (0, 0, 1)
}

// Computed here, not in update(): the boat node reads one output per 4 samples (25 Hz of 100 Hz)
// and the two atan2, a square root and three divisions are a fifth of the update's time.
AttitudeOutput TelltaleAttitudeFilter::output() const {
  AttitudeOutput o;
  if (!state_.initialised) return o;
  o.valid = true;
  if (!state_.updated) {  // the first sample's tilt, rates, weight and quality 0
    tilt_from_accel(state_.up_body, o.heel_rad, o.pitch_rad);
    return o;
  }
  output_from_up(state_.rate_rad_s, state_.up_body, o);
  constexpr double kInvVar0 = 1.0 / 7.6e-5;  // 1 / (0.5 deg)^2
  o.acc_weight = state_.weight;
  o.quality = 1.0 / (1.0 + state_.tilt_var_rad2 * kInvVar0);
  return o;
}

void TelltaleAttitudeFilter::update(const ImuSample& s) {
  // --- Should this sample be used? (gating apart from the algebra, STYLE rule 6) ---
  double dt = 0.0;
  const SampleGate gate = gate_sample(s, state_.initialised, state_.last_t_s, dt,
                                      diag_.rejected_non_finite, diag_.rejected_time);
  if (gate == SampleGate::kReject) return;
  if (gate == SampleGate::kFirst) {
    initialise(s);
    return;
  }
  const Params& p = params_;
  const Rates& k = rates_;
  const bool gyro_sat = s.gyro_body_rad_s.cwiseAbs().maxCoeff() >= k.gyro_sat_rad_s;
  const bool acc_sat = s.acc_body_m_s2.cwiseAbs().maxCoeff() >= k.acc_sat_m_s2;
  const bool gap = dt > p.max_gap_s;
  // One test for the three rare events; their bookkeeping stays off the common path.
  const bool unusual = gyro_sat | acc_sat | gap;
  if (unusual) [[unlikely]] {
    diag_.gyro_saturated += gyro_sat ? 1u : 0u;
    diag_.acc_saturated += acc_sat ? 1u : 0u;
    diag_.gaps += gap ? 1u : 0u;
  }
  // First-order low-pass steps dt / tau (forward Euler; dt << tau, clamped for long steps).
  const auto step = [dt](double inv_tau) { return std::min(1.0, dt * inv_tau); };
  const Eigen::Vector3d gyro = s.gyro_body_rad_s - state_.bias_rad_s;

  // --- Strapdown integration in frame I. A MEMS gyro sample is the output of its decimation
  // filter, close to the mean rate over the interval that ends at the sample: integrate it over
  // that interval (on BROAD this beats the trapezoid, which assumes instantaneous samples, by
  // 0.15 deg of mean inclination RMSE). Over a gap nothing is known about the rotation: the gyro
  // is not integrated and the tilt is left to the accelerometer.
  if (!gap) {
    state_.q_gyro = rotate_by(state_.q_gyro, gyro * dt);
  }
  // R^T (I -> body), built directly from the conjugate (bit-identical to transposing R): two of
  // the three products below are by R^T, and Eigen's column-major product is the packed one.
  const Eigen::Matrix3d rt_gyro = state_.q_gyro.conjugate().toRotationMatrix();
  const Eigen::Vector3d up_i = state_.up_i;  // before this correction
  // The vertical seen in the body: the turn test, the bias and the output all follow from it and
  // from the target seen in the body (rotations preserve dot and cross products), which saves
  // three of the five matrix products the frame-I forms need.
  const Eigen::Vector3d up_b = rt_gyro * up_i;

  // --- Rest detection: gyro and accelerometer steady for rest_min_s -> learn the bias.
  const double a_rest = step(k.rest_lp);
  state_.gyro_rest_lp_rad_s += a_rest * (s.gyro_body_rad_s - state_.gyro_rest_lp_rad_s);
  state_.acc_rest_lp_m_s2 += a_rest * (s.acc_body_m_s2 - state_.acc_rest_lp_m_s2);
  const bool steady =
      !gyro_sat && !acc_sat &&
      (s.gyro_body_rad_s - state_.gyro_rest_lp_rad_s).squaredNorm() <
          p.rest_gyro_rad_s * p.rest_gyro_rad_s &&
      (s.acc_body_m_s2 - state_.acc_rest_lp_m_s2).squaredNorm() <
          p.rest_acc_m_s2 * p.rest_acc_m_s2 &&
      // Once a bias is known, rest also means "the gyro reads that bias": a slow steady turn
      // (a boat bearing away, a launch) passes the deviation tests but not this one.
      (!state_.bias_known || (state_.gyro_rest_lp_rad_s - state_.bias_rad_s).squaredNorm() <
                                 p.rest_bias_match_rad_s * p.rest_bias_match_rad_s);
  state_.rest_time_s = steady ? state_.rest_time_s + dt : 0.0;
  const bool at_rest = state_.rest_time_s >= p.rest_min_s;
  if (at_rest) {
    ++diag_.rest_samples;
    if (!state_.bias_known) {
      // First rest: the gyro's 0.5 s average after 1 s of stillness is the bias (to ~0.05 deg/s).
      state_.bias_rad_s = state_.gyro_rest_lp_rad_s;
      state_.bias_known = true;
    }
    // Later rests refine it slowly: a slow, steady turn that slips under the rest thresholds
    // (a dinghy being launched) must not teach the filter a false bias.
    state_.bias_rad_s += step(k.rest_bias) * (state_.gyro_rest_lp_rad_s - state_.bias_rad_s);
  }

  // --- Accelerometer in frame I; the non-inertial test and the weight (the paper's idea).
  const Eigen::Vector3d acc_i = rt_gyro.transpose() * s.acc_body_m_s2;
  // |a_I - lowpass(a_I)| sees a horizontal acceleration as well as a vertical one, unlike the
  // paper's | |a| - g | (a 1 m/s^2 push sideways changes |a| by 0.05 m/s^2 only).
  // Measured against a 1 s low-pass, not the slow one: a residual bias e rotates gravity in I at
  // rate e, which shows up as g * e * tau here; with tau = 1 s a 1 deg/s error reads 0.17 m/s^2
  // and cannot lock the gate shut.
  // After the step, a_I - lowpass = (1 - a) (a_I - lowpass before), and 1 - a >= 0 (a is clamped
  // to 1): the norm is taken from the difference before the step, so the step itself is not on
  // the way to the weight.
  const double a_fast = step(k.nonin_lp);
  const Eigen::Vector3d fast_diff = acc_i - state_.acc_fast_i;
  state_.acc_fast_i += a_fast * fast_diff;
  const double nonin =
      std::max((1.0 - a_fast) * fast_diff.norm(), std::abs(s.acc_body_m_s2.norm() - p.g_m_s2));
  state_.nonin_hold_m_s2 = std::max(nonin, state_.nonin_hold_m_s2 * (1.0 - step(k.nonin_release)));
  // 1 - (hold - low) / (high - low), with 1 + low / (high - low) precomputed: one product and one
  // difference after the hold.
  double w = k.nonin_one - state_.nonin_hold_m_s2 * k.nonin_range;
  // A vehicle turning while it moves has a centripetal acceleration (a tack: 2.5 m/s * 0.5 rad/s
  // = 1.25 m/s^2 for seconds) that the low-pass would absorb as a tilt. Signature: a horizontal
  // acceleration across the heading, toward the side the vehicle turns to. A rotation in place
  // (a turntable's axis, a hand turning the sensor) has no such correlation.
  // With the vertical up: the bow x (unit), its horizontal part x_h = x - (x.up) up,
  // |x_h|^2 = 1 - (x.up)^2, and a_lat = (up x x_h).a / |x_h| = (up x x).a / |x_h|. Evaluated in
  // the body, where x = (1, 0, 0): x.up = up_b.x and (up x x).a = a.y up_b.z - a.z up_b.y.
  const double yaw_rate = up_b.dot(gyro);  // rate about the vertical
  const double bow_up = up_b.x();
  const double xh2 = 1.0 - bow_up * bow_up;
  double turn = 0.0;
  if (xh2 > 0.09) {
    const Eigen::Vector3d& a = s.acc_body_m_s2;
    // x / sqrt(xh2) as (x / xh2) sqrt(xh2): the division and the square root run side by side
    // instead of one after the other (this is on the way to the weight).
    const double a_lat = (a.y() * up_b.z() - a.z() * up_b.y()) / xh2 * std::sqrt(xh2);
    turn = a_lat * std::clamp(yaw_rate * k.turn_rate, -1.0, 1.0);
  }
  // The low-pass step as (1 - a) m + a turn: the first product is ready before turn is.
  const double a_turn = step(k.turn_lp);
  state_.turn_m_s2 = (1.0 - a_turn) * state_.turn_m_s2 + a_turn * turn;
  state_.turn_hold_m_s2 =
      std::max(state_.turn_m_s2, state_.turn_hold_m_s2 * (1.0 - step(k.turn_release)));
  // 1 - clamp01(x) = clamp01(1 - x), and 1 - (hold - low) / (high - low) as for w above.
  const double w_turn = clamp01(k.turn_one - state_.turn_hold_m_s2 * k.turn_range);
  w = std::max(p.w_min, clamp01(w * w_turn));
  // At rest the motion is inertial by definition: the tilt error accumulated before the bias was
  // known (10 deg/s for a second) must not look like a linear acceleration and lock the gate.
  if (at_rest) w = 1.0;
  if (acc_sat || gap) w = 0.0;  // a clipped vector points nowhere in particular
  state_.weight = w;

  // --- Low-pass in frame I. Fed with every sample: gating its input by the weight would bias
  // the mean that makes oscillations cancel (a shake with sharp stops and gentle starts would
  // leave a residue). Only a turn, a one-sided acceleration by nature, is kept out.
  const double a_lp = at_rest ? step(k.acc_rest) : std::max(p.lp_turn_min, w_turn) * step(k.acc);
  // a_lp waits for the turn test; the differences it scales do not. lp2 + a (lp1' - lp2) with
  // lp1' - lp2 = (lp1 - lp2) + a (a_I - lp1).
  const Eigen::Vector3d lp_d1 = acc_i - state_.acc_lp1_i;
  const Eigen::Vector3d lp_d2 = state_.acc_lp1_i - state_.acc_lp2_i;
  state_.acc_lp1_i += a_lp * lp_d1;
  state_.acc_lp2_i += a_lp * (lp_d2 + a_lp * lp_d1);

  // --- Correction: move the vertical of frame I toward the low-passed specific force (full
  // step at w = 1: the low-pass already is the time constant; a fraction w of the way otherwise,
  // by normalised linear interpolation, where the steps are small). Only the vertical matters
  // for heel and pitch, and the turn test is invariant to a rotation about it, so the correction
  // is this one unit vector rather than a rotation.
  const double l2 = state_.acc_lp2_i.squaredNorm();
  Eigen::Vector3d up_body = up_b;  // the corrected vertical in the body (the output's input)
  if (l2 > 0.25 * p.g_m_s2 * p.g_m_s2) {
    // Only the target's direction matters (a norm off by e moves the result by ~w e theta), so
    // near g one Newton step from 1/g stands in for the square root and the division.
    // (1.5 - 0.5 l2 / g^2) / g as newton_a - newton_b l2: one product and one difference.
    const double l2_rel = l2 * k.inv_g2;
    const double scale_lp =
        std::abs(l2_rel - 1.0) < 0.1 ? k.newton_a - k.newton_b * l2 : 1.0 / std::sqrt(l2);
    const Eigen::Vector3d target = state_.acc_lp2_i * scale_lp;
    const Eigen::Vector3d moved = up_i + w * (target - up_i);
    const double m2 = moved.squaredNorm();
    if (m2 > 1e-6) {  // not a half-turn away (an upside-down start at w ~ 0.5)
      // Steps are small in steady state (|moved| = 1 - O(w theta^2)): there a Newton step to unit
      // length is exact to (1 - m2)^2 < 1e-6; a large step takes the square root.
      const double scale = std::abs(m2 - 1.0) < 1e-3 ? 1.5 - 0.5 * m2 : 1.0 / std::sqrt(m2);
      state_.up_i = moved * scale;
      // The same step seen in the body: R^T is linear, so R^T up_i follows from up_b and R^T
      // target without a product by R^T of the new up_i. R^T target = scale_lp R^T lp2: the
      // product by R^T does not wait for scale_lp.
      const Eigen::Vector3d lp_b = rt_gyro * state_.acc_lp2_i;
      const Eigen::Vector3d target_b = lp_b * scale_lp;
      up_body = (up_b + w * (target_b - up_b)) * scale;
      // Bias in motion: this step's correction is the small rotation w (target x up) of frame I,
      // which is minus the residual bias times dt, seen in the body frame; integrate it slowly
      // (bias_motion_tau_s) so it never fights the low-pass. The bias feeds the next update's
      // integration, so this is the end of the loop-carried chain: the cross product is taken
      // with lp_b, and scale_lp joins w in the one scalar factor.
      if (!at_rest && !gap) {
        state_.bias_rad_s -= lp_b.cross(up_b) * (scale_lp * w * k.bias_motion);
        state_.bias_rad_s =
            state_.bias_rad_s.cwiseMax(-p.max_bias_rad_s).cwiseMin(p.max_bias_rad_s);
      }
    }
  }

  // --- Quality: a rough tilt variance, growing with gyro-only time, saturation and gaps,
  // shrinking while the accelerometer is trusted.
  constexpr double kDriftVar = 1e-6;  // (0.06 deg/s)^2 * s: residual bias after learning
  state_.tilt_var_rad2 += kDriftVar * dt;
  if (unusual) [[unlikely]] {
    state_.tilt_var_rad2 += (gyro_sat ? 1e-4 : 0.0) + (gap ? 1e-2 : 0.0);
  }
  state_.tilt_var_rad2 *= 1.0 - w * step(k.acc);

  // --- What output() needs: the corrected vertical seen in the body, and the body rate.
  state_.up_body = up_body;
  state_.rate_rad_s = gyro;
  state_.updated = true;
}

}  // namespace telltale::fusion
