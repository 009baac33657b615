#include "telltale/fusion/sim/pose_dataset.hpp"

#include <cmath>

namespace telltale::fusion::sim {

PoseWindowSet simulate_pose_windows(std::uint64_t first, int people, int windows_per_pose) {
  PoseWindowSet out;
  for (int i = 0; i < people; ++i) {
    const std::uint64_t seed = first + static_cast<std::uint64_t>(i);
    const Person person = random_person(seed);
    for (int p = 0; p < kPoseCount; ++p) {
      GaitScenario sc;
      sc.site = SensorSite::kPhone;
      sc.rate_hz = 50.0;
      const auto pose = static_cast<PhonePose>(p);
      sc.segments = {
          {Gait::kSlowWalk, pose, 20.0}, {Gait::kWalk, pose, 20.0}, {Gait::kFastWalk, pose, 20.0}};
      const auto run = simulate_gait(sc, person, seed * 16 + static_cast<std::uint64_t>(p));
      PoseFeatureWindow window(2.0);
      // Windows end between 3 s after the walk starts and its end, evenly spaced.
      const double t0 = sc.standing_s + 3.0;
      const double t1 = run.samples.back().imu.t_s - sc.standing_s;
      int next = 0;
      for (const auto& s : run.samples) {
        window.push(s.imu);
        const double t_next = t0 + (t1 - t0) * next / std::max(1, windows_per_pose - 1);
        if (next < windows_per_pose && s.imu.t_s >= t_next) {
          out.features.push_back(window.features());
          out.labels.push_back(pose);
          ++next;
        }
      }
    }
  }
  return out;
}

std::vector<CalibrationWalk> simulate_calibration_walks(std::uint64_t first, int people,
                                                        PhonePose pose, const PoseNetwork& net) {
  std::vector<CalibrationWalk> out;
  for (int i = 0; i < people; ++i) {
    const std::uint64_t seed = first + static_cast<std::uint64_t>(i);
    const Person person = random_person(seed);
    for (Gait g : {Gait::kSlowWalk, Gait::kWalk, Gait::kFastWalk}) {
      GaitScenario sc = straight_phone_walk(g, pose, 40.0);
      sc.rate_hz = 50.0;
      const auto run = simulate_gait(sc, person, seed * 32 + static_cast<std::uint64_t>(g));
      PdrParams params;
      params.step_length.height_m = person.height_m;
      Pdr pdr(params, net);
      CalibrationWalk walk;
      walk.height_m = person.height_m;
      walk.distance_m = run.distance_m;
      // One entry per step counted, the filled-in ones included (they are laid with the step
      // that found them, at its frequency).
      std::size_t counted = 0;
      for (const auto& s : run.samples) {
        const PdrOutput& o = pdr.update(s.imu, s.mag_uT);
        for (; counted < o.steps; ++counted)
          walk.step_hz.push_back(o.step_hz > 0.0 ? o.step_hz : 1.8);
      }
      out.push_back(walk);
    }
  }
  return out;
}

}  // namespace telltale::fusion::sim

namespace telltale::fusion::sim {

double personal_step_scale(const Person& person, std::uint64_t seed, PhonePose pose,
                           double length_m) {
  GaitScenario sc;
  sc.site = SensorSite::kPhone;
  sc.rate_hz = 50.0;
  sc.closed = true;  // the walk ends at the second mark
  sc.path = {{length_m, 0.0}};
  sc.segments = {{Gait::kWalk, pose, 1e6}};
  const auto run = simulate_gait(sc, person, seed);
  PdrParams params;
  params.step_length.height_m = person.height_m;
  Pdr pdr(params);
  for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
  return pdr.output().distance_m > 0.0 ? run.distance_m / pdr.output().distance_m : 1.0;
}

LoopWalkResult simulate_pdr_loop(std::uint64_t seed, LoopVariant variant, bool calibrate,
                                 std::optional<PhonePose> pose) {
  auto sc = *make_gait_scenario("loop", seed);
  Person person = random_person(seed);
  if (variant == LoopVariant::kSinglePose && !pose) pose = sc.segments.front().pose;
  if (pose)
    for (auto& seg : sc.segments) seg.pose = *pose;
  if (variant == LoopVariant::kIdealSensors) {
    sc.errors.acc_bias_m_s2 = sc.errors.gyro_bias_rad_s = sc.errors.mag_bias_uT = 0.0;
    for (int p = 0; p < kPoseCount; ++p) person.mount_yaw_deg[p] = person.mount_tilt_deg[p] = 0.0;
  }
  const auto run = simulate_gait(sc, person, seed);
  PdrParams params;
  params.step_length.height_m = person.height_m;
  // The calibration walk's seed is far from every loop seed, so its noise and biases are its own.
  if (calibrate) params.step_length.scale.fill(personal_step_scale(person, seed + 1000003));
  Pdr pdr(params);
  for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
  LoopWalkResult r;
  r.step_scale = params.step_length.scale[0];
  r.distance_error_fraction = pdr.output().distance_m / run.distance_m - 1.0;
  const auto& last = run.samples.back();
  r.distance_m = run.distance_m;
  r.end_error_m = std::hypot(pdr.output().x_m - last.x_m, pdr.output().y_m - last.y_m);
  r.error_fraction = r.end_error_m / r.distance_m;
  r.steps_true = run.step_times_s.size();
  r.steps_counted = pdr.output().steps;
  for (std::size_t i = 1; i < run.samples.size(); ++i)
    if (run.samples[i].pose != run.samples[i - 1].pose) ++r.switches_true;
  r.switches_detected = pdr.diagnostics().switches;
  return r;
}

}  // namespace telltale::fusion::sim
