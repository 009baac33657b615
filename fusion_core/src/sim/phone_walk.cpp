#include "telltale/fusion/sim/phone_walk.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "telltale/fusion/handheld/walk_ratio.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::fusion::sim {
namespace {

constexpr double kG = kStandardGravity_m_s2;
constexpr double kTilt = 50.0 * M_PI / 180.0;  // the screen tilted toward the face
constexpr double kPressAfterStop_s = 0.5;      // a walk's end as its walker marks it

Eigen::Vector3d normal3(Rng& rng) { return {rng.normal(), rng.normal(), rng.normal()}; }

}  // namespace

Eigen::Matrix3d phone_held_in_front(double heading, double extra_pitch) {
  const Eigen::Vector3d fwd(std::sin(heading), std::cos(heading), 0.0);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d right(std::cos(heading), -std::sin(heading), 0.0);
  const double a = kTilt + extra_pitch;
  Eigen::Matrix3d r;
  r.col(0) = right;
  r.col(1) = fwd * std::cos(a) + up * std::sin(a);
  r.col(2) = -fwd * std::sin(a) + up * std::cos(a);
  return r;
}

PhoneWalk simulate_phone_walk(const std::vector<PhoneSegment>& plan, const PhoneWalkParams& p,
                              std::uint64_t seed) {
  Rng rng(seed);
  Rng mag_rng(seed ^ 0x6d61676e6574ULL);  // the field's noise on a stream of its own
  // The hand's roll with each step, a quarter period after its pitch: every step is a loop in
  // (roll, pitch), and the rate about the vertical gathers its area where the phone's forward
  // axis does not (forward_axis_yaw.hpp). Its share of the pitch, drawn per walker on a stream
  // of its own (the other draws stay as they were): up to +-0.12, a loop direction either way,
  // some 4 deg over a 150 s walk at the most, as the IPIN walks part the two by -0.4 to +3.9 deg.
  const double loop_roll = Rng(seed ^ 0x6c6f6f70ULL).uniform(-0.12, 0.12);
  PhoneWalk w;
  const double dt = 1.0 / p.rate_hz;
  const double speed = p.step_length_m * p.step_hz;
  const double period = 1.0 / p.step_hz;
  double t = 0.0, heading = 0.3;
  double walk_t = 0.0;      // time into the walk in progress (consecutive walking segments)
  double closing_t = -1.0;  // time since the last walk's closing heel strike (< 0: none)
  bool walked = false;
  // Orientations and world accelerations sampled; the gyro is the rotation between samples.
  std::vector<Eigen::Matrix3d> rot;
  std::vector<Eigen::Vector3d> acc_world;
  std::vector<double> times;
  for (std::size_t si = 0; si < plan.size(); ++si) {
    const PhoneSegment& seg = plan[si];
    const double t_start = t;
    const bool walking = seg.phase == PhonePhase::kWalking;
    const bool walk_goes_on =
        walking && si + 1 < plan.size() && plan[si + 1].phase == PhonePhase::kWalking;
    if (walking && closing_t >= 0.0) walk_t = 0.0;  // a new walk from standing
    if (walking) closing_t = -1.0;
    const int n = static_cast<int>(seg.duration_s * p.rate_hz);
    // Handling: a random rotation axis and angle per 1.5 s, in and out smoothly, and the hand's
    // jerks (the angles reach 60-170 deg: rates of 2-7 rad/s).
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
    double angle = 0.0;
    const double heading0 = heading;
    for (int i = 0; i < n; ++i, t += dt) {
      const double ts = t - t_start;
      Eigen::Matrix3d r;
      Eigen::Vector3d a = Eigen::Vector3d::Zero();
      const double tremor = 0.005 * std::sin(2.0 * M_PI * 8.0 * t);
      const double wander = 0.026 * std::sin(2.0 * M_PI * t / 20.0);
      switch (seg.phase) {
        case PhonePhase::kHandling: {
          const double k = std::fmod(ts, 1.5) / 1.5;
          if (std::fmod(ts, 1.5) < dt) {
            axis = normal3(rng).normalized();
            angle = 1.0 + 2.0 * rng.uniform();
          }
          const double env = std::sin(M_PI * k);
          r = phone_held_in_front(heading, 0.0) *
              Eigen::AngleAxisd(angle * env * env, axis).toRotationMatrix();
          a = 3.0 * env *
              Eigen::Vector3d(std::sin(7.0 * t + 1.0), std::sin(5.0 * t), std::sin(11.0 * t + 2.0));
          break;
        }
        case PhonePhase::kStanding:
        case PhonePhase::kPause:
          heading = heading0 + seg.turn_deg * M_PI / 180.0 * std::min(1.0, ts / 2.0);
          r = phone_held_in_front(heading + wander, tremor);
          a = 0.1 * normal3(rng);
          // The walk before ended at its closing heel strike: the trunk settles over a quarter
          // step.
          if (closing_t >= 0.0) {
            a.z() += walking_trunk_up(WalkStep::kClosing, closing_t, period, p.step_length_m,
                                      p.height_m, 1.0);
            closing_t += dt;
          }
          break;
        case PhonePhase::kWalking: {
          heading = heading0 + seg.turn_deg * M_PI / 180.0 * std::min(1.0, ts / 1.5);
          // The trunk's bounce (gait_sim's walker: the first step a push, each after it a heel
          // strike's loading), the forward surge at the step's rate, the lateral sway at the
          // stride's, and the hand's pitch with each step; the horizontal motions build up over
          // the first step and die out over the last. The truth's speed is the walk's from the
          // push to the closing heel strike: n heel strikes cover n steps, what a step counter
          // laying every step at its length lays (the table measures the counting).
          const auto k = std::floor(walk_t / period);
          const double t_in = walk_t - k * period;
          const WalkStep which = k == 0.0 ? WalkStep::kFirst : WalkStep::kWithin;
          const double phase = 2.0 * M_PI * walk_t / period;
          const double ramp_in = walk_t / period;
          const double ramp_out = walk_goes_on ? 1.0 : (seg.duration_s - ts) / period;
          const double blend = std::clamp(std::min(ramp_in, ramp_out), 0.0, 1.0);
          const Eigen::Vector3d fwd(std::sin(heading), std::cos(heading), 0.0);
          const Eigen::Vector3d right(std::cos(heading), -std::sin(heading), 0.0);
          a = walking_trunk_up(which, t_in, period, p.step_length_m, p.height_m, 1.0) *
                  Eigen::Vector3d::UnitZ() +
              blend * (1.2 * std::sin(phase) * fwd + 0.5 * std::sin(0.5 * phase) * right);
          r = phone_held_in_front(heading + wander, tremor + blend * 0.035 * std::sin(phase)) *
              Eigen::AngleAxisd(blend * loop_roll * 0.035 * std::cos(phase),
                                Eigen::Vector3d::UnitY());
          w.truth.x_m += speed * dt * std::sin(heading);
          w.truth.y_m += speed * dt * std::cos(heading);
          w.truth.distance_m += speed * dt;
          w.truth.steps += p.step_hz * dt;
          walk_t += dt;
          break;
        }
      }
      rot.push_back(r);
      acc_world.push_back(a);
      times.push_back(t);
    }
    if (walking) {
      if (!walked) w.truth.walk_start_s = t_start;
      walked = true;
      // A walker stops, then presses "here": the closing heel strike's loading is over within a
      // quarter step, and the press comes after it.
      w.truth.walk_end_s = walk_goes_on ? t : t + kPressAfterStop_s;
      if (!walk_goes_on) closing_t = 0.0;
    } else {
      w.truth.quiet.emplace_back(t_start, t);
    }
  }
  w.truth.heading_rad = heading;
  if (rot.size() < 2) return w;  // no rate without two orientations
  const Eigen::Vector3d earth_uT(0.0, 20.0, -44.0);
  w.samples.reserve(rot.size());
  w.mag_uT.reserve(rot.size());
  for (std::size_t i = 0; i < rot.size(); ++i) {
    ImuSample s;
    s.t_s = times[i];
    const Eigen::Vector3d f_world = acc_world[i] + Eigen::Vector3d(0.0, 0.0, kG);
    s.acc_body_m_s2 = rot[i].transpose() * f_world + 0.05 * normal3(rng);
    // Body rate: the rotation from this sample to the next (the last repeats).
    const std::size_t j = i + 1 < rot.size() ? i : i - 1;
    const Eigen::AngleAxisd d(Eigen::Matrix3d(rot[j].transpose() * rot[j + 1]));
    s.gyro_body_rad_s = d.axis() * d.angle() / dt + p.gyro_bias_rad_s + 0.005 * normal3(rng);
    w.samples.push_back(s);
    w.mag_uT.push_back(rot[i].transpose() * earth_uT + 0.4 * normal3(mag_rng));
  }
  return w;
}

std::vector<PhoneSegment> ipin_like_plan(std::uint64_t seed, double height_m,
                                         PhoneWalkParams& params) {
  Rng rng(seed * 7919 + 17);
  params.step_hz = rng.uniform(1.6, 2.0);
  params.step_length_m = walk_ratio_step_length_m(height_m, params.step_hz);
  params.gyro_bias_rad_s = 0.003 * normal3(rng);
  params.height_m = height_m;
  const double a = rng.uniform(8.0, 25.0), b = rng.uniform(8.0, 25.0);
  const double turn = rng.uniform() < 0.5 ? 90.0 : -90.0;
  // A leg is whole steps (a walk ends at a heel strike), the nearest count to its length.
  const auto leg = [&params](double len) {
    return std::max(1.0, std::round(len / params.step_length_m)) / params.step_hz;
  };
  const int pause_a = static_cast<int>(rng.uniform(0.0, 3.0));  // two of the three inner corners
  std::vector<PhoneSegment> plan = {{PhonePhase::kHandling, rng.uniform(20.0, 40.0)},
                                    {PhonePhase::kStanding, rng.uniform(20.0, 40.0)},
                                    {PhonePhase::kWalking, leg(a)}};
  const double sides[3] = {b, a, b};
  for (int k = 0; k < 3; ++k) {
    if (k != pause_a) plan.push_back({PhonePhase::kPause, rng.uniform(3.0, 10.0)});
    plan.push_back({PhonePhase::kWalking, leg(sides[k]), turn});
  }
  plan.push_back({PhonePhase::kStanding, 5.0});
  return plan;
}

}  // namespace telltale::fusion::sim
