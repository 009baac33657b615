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
  PhoneWalk w;
  const double dt = 1.0 / p.rate_hz;
  const double speed = p.step_length_m * p.step_hz;
  double t = 0.0, heading = 0.3, walk_phase = 0.0;
  bool walked = false;
  // Orientations and world accelerations sampled; the gyro is the rotation between samples.
  std::vector<Eigen::Matrix3d> rot;
  std::vector<Eigen::Vector3d> acc_world;
  std::vector<double> times;
  for (const auto& seg : plan) {
    const double t_start = t;
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
          break;
        case PhonePhase::kWalking: {
          heading = heading0 + seg.turn_deg * M_PI / 180.0 * std::min(1.0, ts / 1.5);
          walk_phase += 2.0 * M_PI * p.step_hz * dt;
          const double ramp = std::min(1.0, ts / 0.3);
          const Eigen::Vector3d fwd(std::sin(heading), std::cos(heading), 0.0);
          const Eigen::Vector3d right(std::cos(heading), -std::sin(heading), 0.0);
          a = ramp * (2.5 * std::sin(walk_phase) * Eigen::Vector3d::UnitZ() +
                      1.2 * std::cos(walk_phase) * fwd + 0.5 * std::sin(0.5 * walk_phase) * right);
          r = phone_held_in_front(heading + wander, tremor + 0.035 * std::sin(walk_phase));
          const double v = speed * ramp;
          w.truth.x_m += v * dt * std::sin(heading);
          w.truth.y_m += v * dt * std::cos(heading);
          w.truth.distance_m += v * dt;
          w.truth.steps += p.step_hz * dt * ramp;
          break;
        }
      }
      rot.push_back(r);
      acc_world.push_back(a);
      times.push_back(t);
    }
    if (seg.phase == PhonePhase::kWalking) {
      if (!walked) w.truth.walk_start_s = t_start;
      walked = true;
      w.truth.walk_end_s = t;
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
  const double speed = params.step_length_m * params.step_hz;
  const double a = rng.uniform(8.0, 25.0), b = rng.uniform(8.0, 25.0);
  const double turn = rng.uniform() < 0.5 ? 90.0 : -90.0;
  // The speed ramps up over 0.3 s: a leg lasts its length at speed plus half the ramp.
  const auto leg = [speed](double len) { return len / speed + 0.15; };
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
