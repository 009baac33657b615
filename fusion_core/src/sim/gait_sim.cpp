#include "telltale/fusion/sim/gait_sim.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace telltale::fusion::sim {
namespace {

constexpr double kG = kStandardGravity_m_s2;
constexpr double kDeg = M_PI / 180.0;
constexpr double kTwoPi = 2.0 * M_PI;

constexpr std::array<std::string_view, kGaitCount> kGaitNames = {"slow-walk", "walk", "fast-walk",
                                                                 "jog", "run"};
constexpr std::array<std::string_view, kPoseCount> kPoseNames = {"hand-held", "call", "pocket",
                                                                 "arm-swing"};

/// Population table (adult averages, e.g. gait-lab cadence/speed surveys): step frequency (Hz),
/// step length / height, stance fraction of the foot cycle, foot clearance (m).
struct GaitRow {
  double step_hz;
  double length_per_height;
  double stance_fraction;
  double clearance_m;
  bool running;
};
constexpr std::array<GaitRow, kGaitCount> kGaitTable = {{
    {1.40, 0.33, 0.66, 0.05, false},  // slow walk ~0.8 m/s
    {1.80, 0.42, 0.62, 0.06, false},  // walk ~1.35 m/s
    {2.10, 0.49, 0.59, 0.07, false},  // fast walk ~1.8 m/s
    {2.55, 0.58, 0.42, 0.10, true},   // jog ~2.6 m/s
    {2.90, 0.75, 0.35, 0.14, true},   // run ~3.8 m/s
}};

/// Gait initiation: the trunk's rise at the first toe-off, as a fraction of a step's loading.
constexpr double kInitiationPush = 0.25;

double minjerk(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}
/// Into a turning point: 0 -> 1 from rest (zero rate and angular acceleration), arriving at zero
/// rate but still decelerating (f''(1) = -12). A foot rolling onto its toes reaches its largest
/// plantar flexion just after toe-off and turns straight back into the swing: its rate crosses
/// zero there, it does not dwell at zero as a minimum-jerk end would.
double into_turn(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (4.0 - 3.0 * x);
}
/// Out of a turning point: its mirror image, 0 -> 1 leaving zero rate already accelerating
/// (f''(0) = 12), arriving at rest.
double out_of_turn(double x) { return 1.0 - into_turn(1.0 - x); }
double minjerk_acc(double x) {  // second derivative with respect to x
  if (x <= 0.0 || x >= 1.0) return 0.0;
  return 60.0 * x - 180.0 * x * x + 120.0 * x * x * x;
}

Eigen::Matrix3d rot_x(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d rot_y(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

/// Seed 003, eqs. (14)-(15): v_walking = M v_sensor.
Eigen::Matrix3d pose_matrix(PhonePose p) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  if (p == PhonePose::kCall) m << 0, 0, -1, 0, -1, 0, -1, 0, 0;
  if (p == PhonePose::kPocket) m << 0, 0, -1, 0, 1, 0, 1, 0, 0;
  return m;
}

/// Where the phone is relative to the chest in each pose (walking frame, m): the hand carries it
/// this far during a switch.
Eigen::Vector3d pose_position(PhonePose p) {
  switch (p) {
    case PhonePose::kHandHeld:
      return {0.35, -0.10, -0.15};
    case PhonePose::kCall:
      return {0.0, 0.12, 0.35};
    case PhonePose::kPocket:
      return {0.10, 0.08, 0.0};
    case PhonePose::kArmSwing:
      return {0.0, -0.25, -0.55};
  }
  return Eigen::Vector3d::Zero();
}

// --- path -------------------------------------------------------------------------------------
struct Piece {
  double s0, length, curvature;  // curvature 1/m, + = left (counter-clockwise)
  double x0, y0, heading0_rad;   // heading clockwise from north
};

class Path {
 public:
  Path(const std::vector<PathLeg>& legs, double radius, double heading0_deg) {
    double s = 0, x = 0, y = 0, h = heading0_deg * kDeg;
    auto add = [&](double len, double curv) {
      if (len <= 0.0) return;
      pieces_.push_back({s, len, curv, x, y, h});
      eval_piece(pieces_.back(), len, x, y, h);
      s += len;
    };
    for (const auto& leg : legs) {
      add(leg.length_m, 0.0);
      if (leg.turn_deg != 0.0)
        add(radius * std::abs(leg.turn_deg) * kDeg, (leg.turn_deg > 0 ? -1.0 : 1.0) / radius);
    }
    total_ = s;
    end_x_ = x;
    end_y_ = y;
  }
  [[nodiscard]] double total() const { return total_; }
  /// Position (east, north) and heading at distance s; beyond the end the path repeats.
  void at(double s, double& x, double& y, double& heading_rad, double& curvature) const {
    double ox = 0, oy = 0;
    if (total_ > 0.0 && s >= total_) {
      const double laps = std::floor(s / total_);
      s -= laps * total_;
      ox = laps * end_x_;
      oy = laps * end_y_;
    }
    const Piece* p = &pieces_.front();
    for (const auto& q : pieces_)
      if (q.s0 <= s) p = &q;
    eval_piece(*p, s - p->s0, x, y, heading_rad);
    x += ox;
    y += oy;
    curvature = p->curvature;
  }

 private:
  static void eval_piece(const Piece& p, double ds, double& x, double& y, double& h) {
    if (p.curvature == 0.0) {
      x = p.x0 + ds * std::sin(p.heading0_rad);
      y = p.y0 + ds * std::cos(p.heading0_rad);
      h = p.heading0_rad;
      return;
    }
    // Left turn (curvature > 0) decreases the clockwise heading.
    const double dh = -ds * p.curvature;
    const double r = 1.0 / p.curvature;
    // Integrate (sin h, cos h) over h from h0 to h0 + dh: ds = -r dh.
    x = p.x0 - r * (-std::cos(p.heading0_rad + dh) + std::cos(p.heading0_rad));
    y = p.y0 - r * (std::sin(p.heading0_rad + dh) - std::sin(p.heading0_rad));
    h = p.heading0_rad + dh;
  }
  std::vector<Piece> pieces_;
  double total_ = 0.0, end_x_ = 0.0, end_y_ = 0.0;
};

struct Step {
  double t0, period_s, length_m, s0;
  Gait gait;
};

/// Quasi-random smooth wobble (hand tremor, head motion): three sines with drawn frequencies.
struct Wobble {
  std::array<double, 9> f{}, ph{};
  void draw(Rng& rng) {
    for (std::size_t i = 0; i < 9; ++i) {
      f[i] = rng.uniform(0.6, 3.0);
      ph[i] = rng.uniform(0.0, kTwoPi);
    }
  }
  /// Three angles (rad) of rms ~ amp.
  [[nodiscard]] Eigen::Vector3d at(double t, double amp) const {
    Eigen::Vector3d v;
    for (int a = 0; a < 3; ++a) {
      double sum = 0;
      for (int j = 0; j < 3; ++j) {
        const auto i = static_cast<std::size_t>(3 * a + j);
        sum += std::sin(kTwoPi * f[i] * t + ph[i]);
      }
      v[a] = amp * sum / std::sqrt(1.5);
    }
    return v;
  }
};

class Simulator {
 public:
  Simulator(const GaitScenario& sc, const Person& person, std::uint64_t seed)
      : sc_(sc),
        p_(person),
        rng_(seed),
        path_(sc.path.empty() ? std::vector<PathLeg>{{84.39, -180.0}, {84.39, -180.0}} : sc.path,
              sc.path.empty() ? 36.5 : sc.corner_radius_m, sc.start_heading_deg) {
    wobble_.draw(rng_);
    for (std::size_t a = 0; a < 3; ++a) {
      acc_bias_[a] = sc.errors.acc_bias_m_s2 * rng_.normal();
      gyro_bias_[a] = sc.errors.gyro_bias_rad_s * rng_.normal();
      mag_bias_[a] = sc.errors.mag_bias_uT * rng_.normal();
    }
    schedule();
  }

  GaitRun run() {
    GaitRun out;
    const double dt = 1.0 / sc_.rate_hz;
    const double t_stop = t_end_ + sc_.standing_s;
    const auto n = static_cast<std::size_t>(std::floor(t_stop / dt)) + 1;
    out.samples.reserve(n);
    for (std::size_t i = 0; i < n; ++i) out.samples.push_back(sample(static_cast<double>(i) * dt));
    // Heel strikes: step 0 starts from a standing foot (none), the closing one ends the walk.
    for (std::size_t k = 1; k < steps_.size(); ++k) {
      out.step_times_s.push_back(steps_[k].t0);
      if (k % 2 == 0) out.foot_step_times_s.push_back(steps_[k].t0);
    }
    out.step_times_s.push_back(t_end_);
    out.foot_step_times_s.push_back(t_end_);  // the final left heel strike closes the last swing
    out.distance_m = s_end_;
    return out;
  }

 private:
  // Segment in force at time t (walk clock starts at standing_s).
  [[nodiscard]] const GaitSegment& segment_at(double t, double* seg_start = nullptr) const {
    double t0 = sc_.standing_s;
    for (std::size_t i = 0; i + 1 < sc_.segments.size(); ++i) {
      if (t < t0 + sc_.segments[i].duration_s) {
        if (seg_start) *seg_start = t0;
        return sc_.segments[i];
      }
      t0 += sc_.segments[i].duration_s;
    }
    if (seg_start) *seg_start = t0;
    return sc_.segments.back();
  }

  void schedule() {
    double total = 0;
    for (const auto& s : sc_.segments) total += s.duration_s;
    double t = sc_.standing_s;
    double s = 0;
    double f = 0, len = 0;
    for (std::size_t k = 0;; ++k) {
      const bool done = sc_.closed ? s >= path_.total() : t >= sc_.standing_s + total;
      if (done && k % 2 == 0) break;
      const Gait g = segment_at(t).gait;
      const double f_target = nominal_step_hz(g, p_);
      const double l_target = nominal_step_length_m(g, p_);
      // Gait changes take a few steps (first-order approach to the new cadence and length).
      f = k == 0 ? f_target : f + 0.35 * (f_target - f);
      len = k == 0 ? l_target : len + 0.35 * (l_target - len);
      const double asym = (k % 2 == 0) ? 0.985 : 1.015;
      const double period = asym * (1.0 + 0.02 * rng_.normal()) / f;
      const double step_len = len * (1.0 + 0.03 * rng_.normal());
      steps_.push_back({t, period, step_len, s, g});
      t += period;
      s += step_len;
    }
    t_end_ = t;
    s_end_ = s;
  }

  /// Index of the step in progress at t (or -1 before the walk, steps_.size() after).
  [[nodiscard]] std::ptrdiff_t step_index(double t) const {
    if (steps_.empty() || t < steps_.front().t0) return -1;
    if (t >= t_end_) return static_cast<std::ptrdiff_t>(steps_.size());
    const auto it = std::upper_bound(steps_.begin(), steps_.end(), t,
                                     [](double v, const Step& st) { return v < st.t0; });
    return (it - steps_.begin()) - 1;
  }

  struct Body {
    double s = 0, v = 0;
    Eigen::Vector3d acc_w = Eigen::Vector3d::Zero();  // walking-frame acceleration
    Eigen::Vector3d trunk = Eigen::Vector3d::Zero();  // roll, pitch, yaw oscillation, rad
    /// Stride phase (0..1 over two steps) and its first two time derivatives, C1 in time.
    double stride_phase = 0, stride_rate = 0, stride_rate_d = 0;
    /// Arm-swing amplitude (rad) and its first two time derivatives, C1 in time.
    double arm_amp = 0, arm_amp_d = 0, arm_amp_dd = 0;
    double step_hz = 0, step_len = 0;
    Gait gait = Gait::kWalk;
    bool moving = false;
    double blend = 0.0;  ///< 0 standing .. 1 walking: trunk and arm motion build up and die out
  };

  /// Arm-swing amplitude of a step (rad): full swing from a 0.7 m step up.
  [[nodiscard]] double arm_amplitude(std::size_t k) const {
    return p_.arm_swing_deg * kDeg * std::min(1.0, steps_[k].length_m / 0.7);
  }

  /// Stride phase and arm-swing amplitude at phase ph of step k, with their time derivatives.
  /// The phase runs k/2 .. (k+1)/2 over the step along a cubic Hermite curve whose rate at each
  /// heel strike is the mean of the two steps' rates; the amplitude moves between knot values
  /// (the mean of two steps' amplitudes; 0 when the walk starts and ends) along a smoothstep.
  /// Both are C1 across steps: the arm's angular velocity never jumps.
  void stride_motion(std::size_t k, double ph, Body& b) const {
    const std::size_t n = steps_.size();
    const double T = steps_[k].period_s;
    const auto rate = [&](std::size_t i) { return 0.5 / steps_[i].period_s; };
    const double r0 = k == 0 ? rate(0) : 0.5 * (rate(k - 1) + rate(k));
    const double r1 = k + 1 == n ? rate(k) : 0.5 * (rate(k) + rate(k + 1));
    const double u = ph, u2 = u * u, u3 = u2 * u;
    const double m0 = T * r0, m1 = T * r1;  // knot slopes in stride per unit of ph
    b.stride_phase = 0.5 * static_cast<double>(k % 2) + m0 * (u3 - 2.0 * u2 + u) +
                     0.5 * (3.0 * u2 - 2.0 * u3) + m1 * (u3 - u2);
    b.stride_rate =
        (m0 * (3.0 * u2 - 4.0 * u + 1.0) + 0.5 * (6.0 * u - 6.0 * u2) + m1 * (3.0 * u2 - 2.0 * u)) /
        T;
    b.stride_rate_d =
        (m0 * (6.0 * u - 4.0) + 0.5 * (6.0 - 12.0 * u) + m1 * (6.0 * u - 2.0)) / (T * T);
    const double a0 = k == 0 ? 0.0 : 0.5 * (arm_amplitude(k - 1) + arm_amplitude(k));
    const double a1 = k + 1 == n ? 0.0 : 0.5 * (arm_amplitude(k) + arm_amplitude(k + 1));
    b.arm_amp = a0 + (a1 - a0) * (3.0 * u2 - 2.0 * u3);
    b.arm_amp_d = (a1 - a0) * (6.0 * u - 6.0 * u2) / T;
    b.arm_amp_dd = (a1 - a0) * (6.0 - 12.0 * u) / (T * T);
  }

  /// The trunk's vertical acceleration (m/s^2, up) t_in seconds into step k; k = steps_.size():
  /// after the walk, t_in seconds after its closing heel strike.
  ///
  /// Walking: walking_trunk_up (gait_sim.hpp). Running, a spring-mass: the vertical force a
  /// half sine over the contact, mean g over the step. A run starts and ends as a walk does:
  /// step 0 begins with the push of the first toe-off (`kInitiationPush` of a contact), and the
  /// last step ends at the landing that ends the last flight -- the trunk cannot stop in mid-air.
  [[nodiscard]] double trunk_up(std::size_t k, double t_in) const {
    const bool closing = k >= steps_.size();
    const Step& st = steps_[closing ? steps_.size() - 1 : k];
    const GaitRow& row = kGaitTable[static_cast<std::size_t>(st.gait)];
    const double T = st.period_s, L = st.length_m;
    if (!row.running) {
      const WalkStep which = closing  ? WalkStep::kClosing
                             : k == 0 ? WalkStep::kFirst
                                      : WalkStep::kWithin;
      return walking_trunk_up(which, t_in, T, L, p_.height_m, p_.bounce_scale);
    }
    const double ph = t_in / T;
    const double beta = st.gait == Gait::kJog ? 0.72 : 0.62;
    const double peak = p_.bounce_scale * 0.5 * M_PI * kG / beta;
    const double g = p_.bounce_scale * kG;
    const double impact = 4.0 * std::exp(-t_in / 0.02) * std::sin(kTwoPi * 15.0 * t_in);
    // The landing: the contact's force rises as in a stride and leaves the runner standing.
    if (closing)
      return ph < beta ? peak * std::sin(M_PI * ph / beta) - g * (1.0 - ph / beta) + impact : 0.0;
    const double contact = ph < beta ? peak * std::sin(M_PI * ph / beta) : 0.0;
    // From standing the first contact is a push, not a landing.
    if (k == 0) return ph < beta ? kInitiationPush * (contact - g) * (ph / beta) : -g;
    return contact - g + impact;
  }

  [[nodiscard]] Body body(double t) const {
    Body b;
    const auto k = step_index(t);
    if (k < 0) {
      b.gait = sc_.segments.front().gait;
      return b;
    }
    if (k >= static_cast<std::ptrdiff_t>(steps_.size())) {
      b.s = s_end_;
      b.gait = steps_.back().gait;
      b.acc_w.z() = trunk_up(steps_.size(), t - t_end_);
      return b;
    }
    const Step& st = steps_[static_cast<std::size_t>(k)];
    const GaitRow& row = kGaitTable[static_cast<std::size_t>(st.gait)];
    const double T = st.period_s, L = st.length_m, f = 1.0 / T;
    const double ph = (t - st.t0) / T;
    b.moving = true;
    b.gait = st.gait;
    b.step_hz = f;
    b.step_len = L;
    stride_motion(static_cast<std::size_t>(k), ph, b);
    const double e = row.running ? 0.08 : 0.12;
    b.s = st.s0 + L * (ph + e * std::sin(kTwoPi * ph) / kTwoPi);
    b.v = L / T * (1.0 + e * std::cos(kTwoPi * ph));
    const double a_fwd = -(L / (T * T)) * e * kTwoPi * std::sin(kTwoPi * ph);
    const double a_up = trunk_up(static_cast<std::size_t>(k), t - st.t0);
    const double sway = row.running ? 0.012 : 0.025;
    const double th = kTwoPi * b.stride_phase, th_d = kTwoPi * b.stride_rate;
    const double a_lat =
        sway * (kTwoPi * b.stride_rate_d * std::cos(th) - th_d * th_d * std::sin(th));
    b.acc_w = {a_fwd, a_lat, a_up};
    const double yaw_amp = (row.running ? 5.0 : 3.0) * kDeg;
    b.trunk = {2.0 * kDeg * std::cos(kTwoPi * b.stride_phase), 1.5 * kDeg * std::cos(kTwoPi * ph),
               yaw_amp * std::sin(kTwoPi * b.stride_phase)};
    // The trunk's sway and the hand's tremor build up over the first step and die out over the
    // last, so the phone's orientation stays continuous when the walk starts and stops (a jump
    // is no rotation a body can make, and a gyro sampled at it read 11-22 rad/s for one sample).
    // The arm swing builds up and dies out with its amplitude (stride_motion).
    const double ramp_in = (t - steps_.front().t0) / steps_.front().period_s;
    const double ramp_out = (t_end_ - t) / steps_.back().period_s;
    b.blend = minjerk(std::clamp(std::min(ramp_in, ramp_out), 0.0, 1.0));
    b.trunk *= b.blend;
    return b;
  }

  /// World rotation of the walking frame at path distance s (x forward, y left, z up in ENU).
  [[nodiscard]] Eigen::Matrix3d walk_frame(double s, double* heading = nullptr,
                                           double* curvature = nullptr, double* x = nullptr,
                                           double* y = nullptr) const {
    double px, py, h, c;
    path_.at(s, px, py, h, c);
    if (heading) *heading = h;
    if (curvature) *curvature = c;
    if (x) *x = px;
    if (y) *y = py;
    Eigen::Matrix3d r;
    r.col(0) = Eigen::Vector3d(std::sin(h), std::cos(h), 0.0);
    r.col(1) = Eigen::Vector3d(-std::cos(h), std::sin(h), 0.0);
    r.col(2) = Eigen::Vector3d::UnitZ();
    return r;
  }

  // --- phone ----------------------------------------------------------------------------------
  /// Orientation of the phone relative to the walking frame, and its extra acceleration
  /// (walking frame) in a pose, given the body state.
  void phone_in_pose(PhonePose pose, double t, const Body& b, Eigen::Matrix3d& osc_out,
                     Eigen::Matrix3d& mount, Eigen::Vector3d& acc_w) const {
    const auto ip = static_cast<std::size_t>(pose);
    const Eigen::Matrix3d mis =
        rot_z(p_.mount_yaw_deg[ip] * kDeg) * rot_y(p_.mount_tilt_deg[ip] * kDeg);
    const Eigen::Vector3d& tr = b.trunk;
    const double still = 0.2 + 0.8 * b.blend;  // a person standing holds the phone steadier
    Eigen::Matrix3d osc = Eigen::Matrix3d::Identity();
    Eigen::Vector3d gain(1, 1, 1);
    acc_w = Eigen::Vector3d::Zero();
    switch (pose) {
      case PhonePose::kHandHeld: {
        // Arm-damped trunk motion, tremor, phone tilted 25 deg up toward the face.
        const Eigen::Vector3d w = wobble_.at(t, still * 1.5 * kDeg) + 0.5 * tr;
        osc = rot_z(w.z()) * rot_y(w.y() - 25.0 * kDeg) * rot_x(w.x());
        gain = {0.8, 0.6, 0.75};
        break;
      }
      case PhonePose::kCall: {
        const Eigen::Vector3d w = wobble_.at(t, still * 0.6 * kDeg) + 0.25 * tr;
        osc = rot_z(w.z()) * rot_y(w.y()) * rot_x(w.x());
        gain = {0.9, 0.45, 0.85};
        break;
      }
      case PhonePose::kPocket:
        osc = rot_z(tr.z()) * rot_y(tr.y()) * rot_x(tr.x());
        break;
      case PhonePose::kArmSwing: {
        // Pendulum from the shoulder at stride frequency, in phase with the opposite leg: the
        // hand is furthest forward when the opposite foot strikes (the left foot strikes at even
        // steps, stride phase 0) and furthest back when the foot on its own side does. alpha > 0
        // = hand forward and up; the phone pitches up with the arm. alpha = a(t) cos(theta(t))
        // with the amplitude and the phase both C1 in time, so the reported acceleration
        // r alpha'' integrates to the arm's true velocity (a phase rate that jumps at a step
        // boundary would hide an impulse the accelerometer never sees).
        const double r = 0.38 * p_.height_m;
        const double a = b.arm_amp, a_d = b.arm_amp_d, a_dd = b.arm_amp_dd;
        const double th = kTwoPi * b.stride_phase, th_d = kTwoPi * b.stride_rate,
                     th_dd = kTwoPi * b.stride_rate_d;
        const double sn = std::sin(th), cs = std::cos(th);
        const double alpha = a * cs;
        const double alpha_d = a_d * cs - a * th_d * sn;
        const double alpha_dd =
            a_dd * cs - 2.0 * a_d * th_d * sn - a * (th_dd * sn + th_d * th_d * cs);
        acc_w = {r * (alpha_dd * std::cos(alpha) - alpha_d * alpha_d * std::sin(alpha)), 0.0,
                 r * (alpha_dd * std::sin(alpha) + alpha_d * alpha_d * std::cos(alpha))};
        osc = rot_z(0.5 * tr.z()) * rot_y(-alpha);
        break;
      }
    }
    acc_w += gain.cwiseProduct(b.acc_w);
    osc_out = osc;
    mount = pose_matrix(pose) * mis;
  }

  /// Phone orientation in the world at t and its acceleration (world), with pose switches.
  void phone(double t, Eigen::Matrix3d& r_ws, Eigen::Vector3d& acc_world, PhonePose& pose,
             bool& switching, Body* body_out = nullptr) const {
    const Body b = body(t);
    if (body_out) *body_out = b;
    double heading, curv;
    const Eigen::Matrix3d r_wf = walk_frame(b.s, &heading, &curv);
    double seg_start = 0;
    const GaitSegment& seg = segment_at(t, &seg_start);
    Eigen::Matrix3d osc, mount;
    Eigen::Vector3d acc_w;
    phone_in_pose(seg.pose, t, b, osc, mount, acc_w);
    Eigen::Matrix3d r_rel = osc * mount;
    pose = seg.pose;
    switching = false;
    // Previous segment's pose while the switch is in progress.
    if (t >= sc_.standing_s && t < seg_start + sc_.switch_s && seg_start > sc_.standing_s) {
      const GaitSegment& prev = segment_at(seg_start - 1e-9);
      if (prev.pose != seg.pose) {
        const double u = (t - seg_start) / sc_.switch_s;
        const double w = minjerk(u);
        Eigen::Matrix3d osc_old, mount_old;
        Eigen::Vector3d acc_old;
        phone_in_pose(prev.pose, t, b, osc_old, mount_old, acc_old);
        // The hand turns the phone from one fixed mounting to the other along one path (slerp of
        // the constant mountings, so the path cannot flip even for a half turn) while the
        // small motions of the two poses blend.
        const Eigen::Quaterniond q_mount =
            Eigen::Quaterniond(mount_old).slerp(w, Eigen::Quaterniond(mount));
        const Eigen::Quaterniond q_osc =
            Eigen::Quaterniond(osc_old).slerp(w, Eigen::Quaterniond(osc));
        r_rel = (q_osc * q_mount).toRotationMatrix();
        const Eigen::Vector3d d = pose_position(seg.pose) - pose_position(prev.pose);
        acc_w =
            (1.0 - w) * acc_old + w * acc_w + d * minjerk_acc(u) / (sc_.switch_s * sc_.switch_s);
        switching = true;
        if (w < 0.5) pose = prev.pose;
      }
    }
    // Turning along the path: centripetal acceleration toward the centre of the turn.
    acc_w.y() += b.v * b.v * curv;
    r_ws = r_wf * r_rel;
    acc_world = r_wf * acc_w;
  }

  // --- foot -----------------------------------------------------------------------------------
  /// Toe position (world ENU) and foot orientation of the left (instrumented) foot at t.
  void foot(double t, Eigen::Vector3d& pos, Eigen::Matrix3d& r_ws,
            Eigen::Vector3d& impact_w) const {
    impact_w.setZero();
    auto k = step_index(t);
    double s_toe = 0, height = 0, pitch = 0, roll = 0, yaw = 0;
    const double lift = 0.26 * p_.height_m / 1.75;  // foot length, m
    if (k < 0 || steps_.empty()) {
      s_toe = 0.3;
    } else {
      // The left foot's cycle: from its heel strike (even steps) to its next. After the walk's
      // closing heel strike (t_end_) the foot stays on the ground: a cycle that never lifts,
      // whose heel strike still slaps the foot flat and rings (until December 2026 the foot
      // snapped flat in one sample there: 35 rad/s for 4 ms).
      const bool closing = k >= static_cast<std::ptrdiff_t>(steps_.size());
      if (!closing && k % 2 == 1) --k;
      const Step& st = closing ? steps_.back() : steps_[static_cast<std::size_t>(k)];
      const std::size_t k2 = static_cast<std::size_t>(k) + 2;
      const double t0 = closing ? t_end_ : st.t0;
      const double s0 = closing ? s_end_ : st.s0;
      const double t_next = closing              ? t_end_ + 2.0 * st.period_s
                            : k2 < steps_.size() ? steps_[k2].t0
                                                 : t_end_;
      const double s_next = closing ? s_end_ : k2 < steps_.size() ? steps_[k2].s0 : s_end_;
      const GaitRow& row = kGaitTable[static_cast<std::size_t>(st.gait)];
      const double tc = t_next - t0;
      const double beta = row.stance_fraction;
      const double hs = (row.running ? 0.5 : 1.0) * p_.heel_strike_deg * kDeg;
      const double to = (row.running ? 1.15 : 1.0) * p_.toe_off_deg * kDeg;
      const double u_slap = row.running ? 0.05 : 0.10;
      const double u = closing ? std::min((t - t0) / tc, u_slap) : (t - t0) / tc;  // flat after
      const double u_heel_off = beta - (row.running ? 0.15 : 0.22);
      const bool first = k == 0;  // the walk starts from a standing foot: no heel strike
      s_toe = s0 + 0.3;
      if (u < beta) {
        if (u < u_slap && !first) {
          pitch = -hs * (1.0 - minjerk(u / u_slap));
          roll = p_.strike_roll_deg * kDeg * (1.0 - minjerk(u / u_slap));
          height = lift * std::sin(-pitch);
        } else if (u >= u_heel_off) {
          pitch = to * into_turn((u - u_heel_off) / (beta - u_heel_off));
        }
      } else {
        const double v = (u - beta) / (1.0 - beta);
        pitch = to + (-hs - to) * out_of_turn(v);
        s_toe += (s_next - s0) * minjerk(v);
        const double s = std::sin(M_PI * v);
        height = row.clearance_m * s * s + lift * std::sin(hs) * minjerk(v);
        roll = (p_.swing_roll_deg * s * s + p_.strike_roll_deg * minjerk(v)) * kDeg;
        yaw = p_.swing_yaw_deg * kDeg * s * s;
      }
      // Heel-strike and foot-flat impacts (decaying ringing of shoe and tissue).
      const double speed = closing ? (s_end_ - steps_.back().s0) / st.period_s : (s_next - s0) / tc;
      const double amp = (row.running ? 9.0 : 6.0) * speed + 5.0;
      const double t_in = t - t0;
      if (!first) {
        impact_w.z() += amp * std::exp(-t_in / 0.012) * std::sin(kTwoPi * 30.0 * t_in);
        impact_w.x() -= 0.5 * amp * std::exp(-t_in / 0.012) * std::sin(kTwoPi * 25.0 * t_in);
        const double t_ff = t - (t0 + u_slap * tc);
        if (t_ff > 0.0)
          impact_w.z() += 0.4 * amp * std::exp(-t_ff / 0.01) * std::sin(kTwoPi * 35.0 * t_ff);
      }
    }
    double heading, x, y;
    const Eigen::Matrix3d r_wf = walk_frame(s_toe, &heading, nullptr, &x, &y);
    pos = Eigen::Vector3d(x, y, height) + r_wf * Eigen::Vector3d(0.0, 0.1, 0.0);
    r_ws = r_wf * rot_z(-7.0 * kDeg + yaw) * rot_y(pitch) * rot_x(roll);  // 7 deg toe-out
    impact_w = r_wf * impact_w;
  }

  static Eigen::Vector3d rate_from(const Eigen::Matrix3d& r_minus, const Eigen::Matrix3d& r_plus,
                                   double h) {
    const Eigen::AngleAxisd aa(r_plus * r_minus.transpose());
    return aa.axis() * aa.angle() / (2.0 * h);  // world frame
  }

  GaitSample sample(double t) {
    GaitSample out;
    constexpr double h = 1e-3;
    Eigen::Matrix3d r_ws;
    Eigen::Vector3d acc_world, omega_world;
    Body b;
    if (sc_.site == SensorSite::kPhone) {
      Eigen::Matrix3d r_m, r_p;
      PhonePose pose_m, pose_p;
      bool sw_m, sw_p;
      Eigen::Vector3d a_m, a_p;
      phone(t - h, r_m, a_m, pose_m, sw_m);
      phone(t + h, r_p, a_p, pose_p, sw_p);
      phone(t, r_ws, acc_world, out.pose, out.switching, &b);
      omega_world = rate_from(r_m, r_p, h);
    } else {
      b = body(t);
      Eigen::Vector3d p_m, p_0, p_p, imp;
      Eigen::Matrix3d r_m, r_p;
      foot(t - 2 * h, p_m, r_m, imp);
      foot(t + 2 * h, p_p, r_p, imp);
      foot(t, p_0, r_ws, imp);
      acc_world = (p_p - 2.0 * p_0 + p_m) / (4.0 * h * h) + imp;
      omega_world = rate_from(r_m, r_p, 2 * h);
      out.pose = segment_at(t).pose;
    }
    const SensorErrors& e = sc_.errors;
    Eigen::Vector3d f = r_ws.transpose() * (acc_world + Eigen::Vector3d(0, 0, kG));
    Eigen::Vector3d w = r_ws.transpose() * omega_world;
    Eigen::Vector3d m = r_ws.transpose() * Eigen::Vector3d(0.0, 20.0, -44.0);
    for (std::size_t a = 0; a < 3; ++a) {
      const auto ai = static_cast<Eigen::Index>(a);
      f[ai] = std::clamp(f[ai] + acc_bias_[a] + e.acc_noise_m_s2 * rng_.normal(), -e.acc_range_m_s2,
                         e.acc_range_m_s2);
      w[ai] = std::clamp(w[ai] + gyro_bias_[a] + e.gyro_noise_rad_s * rng_.normal(),
                         -e.gyro_range_rad_s, e.gyro_range_rad_s);
      m[ai] += mag_bias_[a] + e.mag_noise_uT * rng_.normal();
    }
    out.imu.t_s = t;
    out.imu.acc_body_m_s2 = f;
    out.imu.gyro_body_rad_s = w;
    out.mag_uT = m;
    double heading;
    (void)walk_frame(b.s, &heading, nullptr, &out.x_m, &out.y_m);
    out.heading_deg = std::fmod(heading / kDeg + 720.0, 360.0);
    out.distance_m = b.s;
    out.gait = b.gait;
    out.step_hz = b.step_hz;
    out.step_length_m = b.step_len;
    const auto k = step_index(t);
    out.steps = k < 0 ? 0 : static_cast<int>(k);  // heel strikes so far (none at step 0's start)
    int foot = 0;
    for (std::size_t i = 2; i < steps_.size(); i += 2)
      if (steps_[i].t0 <= t) ++foot;
    if (t >= t_end_) ++foot;
    out.foot_steps = foot;
    return out;
  }

  const GaitScenario& sc_;
  Person p_;
  Rng rng_;
  Path path_;
  Wobble wobble_;
  std::vector<Step> steps_;
  double t_end_ = 0.0, s_end_ = 0.0;
  std::array<double, 3> acc_bias_{}, gyro_bias_{}, mag_bias_{};
};

}  // namespace

double walking_trunk_up(WalkStep step, double t_in_s, double period_s, double length_m,
                        double height_m, double bounce_scale) {
  const double T = period_s;
  const double w2 = (kTwoPi / T) * (kTwoPi / T);
  const double ph = t_in_s / T;
  const double leg = 0.53 * height_m;
  const double half = std::asin(std::min(0.9, length_m / (2.0 * leg)));
  const double amp = 0.3 * bounce_scale * leg * (1.0 - std::cos(half)) * w2;
  const double impact = 0.35 * amp * std::exp(-t_in_s / 0.03) * std::sin(kTwoPi * 12.0 * t_in_s);
  // The closing heel strike's loading, a quarter step down to standing.
  if (step == WalkStep::kClosing) return ph < 0.25 ? amp * std::cos(kTwoPi * ph) + impact : 0.0;
  // The push: a rise and fall over the quarter step a loading would take (net zero: the trunk
  // leaves and returns to its standing height).
  const bool first = step == WalkStep::kFirst;
  if (first && ph < 0.25) return kInitiationPush * amp * std::sin(4.0 * kTwoPi * ph);
  return amp * std::cos(kTwoPi * ph) + (first ? 0.0 : impact);
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = uniform();
  while (u1 <= 1e-300) u1 = uniform();
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(kTwoPi * u2);
  has_spare_ = true;
  return r * std::cos(kTwoPi * u2);
}

std::string_view gait_name(Gait g) { return kGaitNames[static_cast<std::size_t>(g)]; }
std::optional<Gait> gait_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kGaitNames.size(); ++i)
    if (kGaitNames[i] == name) return static_cast<Gait>(i);
  return std::nullopt;
}
std::string_view pose_name(PhonePose p) { return kPoseNames[static_cast<std::size_t>(p)]; }
std::optional<PhonePose> pose_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kPoseNames.size(); ++i)
    if (kPoseNames[i] == name) return static_cast<PhonePose>(i);
  return std::nullopt;
}

Person random_person(std::uint64_t seed) {
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + 17);
  Person p;
  p.height_m = rng.uniform(1.55, 1.95);
  p.cadence_scale = rng.uniform(0.92, 1.08);
  p.step_scale = rng.uniform(0.92, 1.08);
  p.bounce_scale = rng.uniform(0.8, 1.2);
  p.arm_swing_deg = rng.uniform(22.0, 40.0);
  p.toe_off_deg = rng.uniform(28.0, 42.0);
  p.heel_strike_deg = rng.uniform(14.0, 26.0);
  for (int i = 0; i < kPoseCount; ++i) {
    // How differently people hold a phone: a few degrees of yaw, more of tilt.
    p.mount_yaw_deg[i] = 2.0 * rng.normal();
    p.mount_tilt_deg[i] = 6.0 * rng.normal();
  }
  // Drawn last, so that every person's other figures stay what they were.
  p.swing_roll_deg = rng.uniform(4.0, 12.0);
  p.swing_yaw_deg = rng.uniform(3.0, 9.0);
  p.strike_roll_deg = rng.uniform(2.0, 8.0);
  return p;
}

double nominal_step_hz(Gait g, const Person& p) {
  // Taller people step slower (pendulum legs): cadence ~ height^-0.5 about 1.75 m.
  return kGaitTable[static_cast<std::size_t>(g)].step_hz * p.cadence_scale *
         std::sqrt(1.75 / p.height_m);
}

double nominal_step_length_m(Gait g, const Person& p) {
  return kGaitTable[static_cast<std::size_t>(g)].length_per_height * p.height_m * p.step_scale;
}

GaitRun simulate_gait(const GaitScenario& scenario, const Person& person, std::uint64_t seed) {
  GaitScenario sc = scenario;
  if (sc.segments.empty()) sc.segments.push_back({});
  Simulator sim(sc, person, seed);
  return sim.run();
}

GaitScenario straight_phone_walk(Gait gait, PhonePose pose, double duration_s) {
  GaitScenario sc;
  sc.site = SensorSite::kPhone;
  sc.segments = {{gait, pose, duration_s}};
  sc.path = {{1000.0, 0.0}};
  return sc;
}

std::optional<GaitScenario> make_gait_scenario(std::string_view name, std::uint64_t seed) {
  GaitScenario sc;
  sc.name = std::string(name);
  auto rest = name;
  auto take = [&rest]() {
    // Splits the next dash-separated word, keeping multi-word gait and pose names together.
    for (std::string_view w : {"slow-walk", "fast-walk", "hand-held", "arm-swing"})
      if (rest.substr(0, w.size()) == w) {
        rest.remove_prefix(std::min(rest.size(), w.size() + 1));
        return w;
      }
    const auto dash = rest.find('-');
    const std::string_view w = rest.substr(0, dash);
    rest.remove_prefix(dash == std::string_view::npos ? rest.size() : dash + 1);
    return w;
  };
  const std::string_view site = take();
  PhonePose pose = PhonePose::kPocket;
  if (site == "foot") {
    sc.site = SensorSite::kFoot;
    sc.rate_hz = 100.0;
  } else if (site == "body" || site == "phone") {
    sc.site = SensorSite::kPhone;
    sc.rate_hz = 50.0;
  } else if (site == "loop") {
    Rng rng(seed + 101);
    sc.site = SensorSite::kPhone;
    sc.rate_hz = 50.0;
    sc.closed = true;
    const double w = rng.uniform(20.0, 40.0), h = rng.uniform(10.0, 25.0);
    const double turn = rng.uniform() < 0.5 ? 90.0 : -90.0;
    sc.path = {{w, turn}, {h, turn}, {w, turn}, {h, turn}};
    sc.start_heading_deg = rng.uniform(0.0, 360.0);
    // Poses in a random order with switches every 20-40 s; normal walking (as in seed 003).
    int last = -1;
    for (int i = 0; i < 8; ++i) {
      int p = static_cast<int>(rng.uniform() * kPoseCount) % kPoseCount;
      if (p == last) p = (p + 1) % kPoseCount;
      last = p;
      sc.segments.push_back({Gait::kWalk, static_cast<PhonePose>(p), rng.uniform(20.0, 40.0)});
    }
    return rest.empty() ? std::optional<GaitScenario>(sc) : std::nullopt;
  } else {
    return std::nullopt;
  }
  if (site == "phone" && rest != "switch") {
    const auto p = pose_from_name(take());
    if (!p) return std::nullopt;
    pose = *p;
  }
  const std::string_view what = take();
  if (!rest.empty()) return std::nullopt;
  if (what == "mixed") {
    for (Gait g : {Gait::kSlowWalk, Gait::kWalk, Gait::kFastWalk, Gait::kJog, Gait::kRun,
                   Gait::kFastWalk, Gait::kWalk})
      sc.segments.push_back({g, pose, 30.0});
  } else if (what == "switch" && site == "phone") {
    for (PhonePose p : {PhonePose::kHandHeld, PhonePose::kCall, PhonePose::kPocket,
                        PhonePose::kArmSwing, PhonePose::kHandHeld})
      sc.segments.push_back({Gait::kWalk, p, 30.0});
  } else if (const auto g = gait_from_name(what)) {
    sc.segments.push_back({*g, pose, 60.0});
  } else {
    return std::nullopt;
  }
  return sc;
}

std::vector<std::string> gait_scenario_examples() {
  return {"foot-walk",        "foot-run",     "foot-mixed", "body-jog", "phone-arm-swing-walk",
          "phone-call-mixed", "phone-switch", "loop"};
}

}  // namespace telltale::fusion::sim
