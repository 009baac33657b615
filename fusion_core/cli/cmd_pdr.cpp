// fusion_cli pdr: IMU.csv -> TRACK.csv (one row per step) + JSON summary (SPEC section 6).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "csv.hpp"
#include "gait_io.hpp"
#include "telltale/fusion/foot_pdr.hpp"
#include "telltale/fusion/handheld_pdr.hpp"
#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/trunk_pdr.hpp"

namespace telltale::cli {
namespace {

struct PdrOptions {
  std::string in;
  std::string out;
  double height_m = 0.0;
  double step_scale = 1.0;
  std::string mount = "phone";
};

/// A phone held in front (reading / texting pose, real phone walks): HandheldPdr.
void run_handheld(const PdrOptions& o, const std::vector<ImuRecord>& records, bool has_gyro,
                  bool has_mag, std::size_t repeated) {
  fusion::HandheldPdrParams params;
  params.height_m = o.height_m;
  params.step_scale = o.step_scale;
  const HandheldWalk walk = run_handheld_walk(records, params);
  io::CsvWriter track(o.out, {"t_s", "x_m", "y_m", "heading_deg", "pose", "steps", "distance_m",
                              "step_length_m", "cadence_spm", "switching"});
  auto write = [&track](const fusion::HandheldStep& r) {
    track.row({r.t_s, r.x_m, r.y_m, r.heading_deg, 0.0, static_cast<double>(r.steps),
               r.distance_m, r.length_m, 60.0 * r.step_hz, 0.0});
  };
  if (!records.empty()) {
    fusion::HandheldStep first;
    first.t_s = records.front().imu.t_s;
    write(first);
  }
  for (const auto& s : walk.steps) write(s);
  track.close();
  const fusion::HandheldStep f = walk.steps.empty() ? fusion::HandheldStep{} : walk.steps.back();
  const auto& b = walk.gyro_bias_rad_s;
  std::printf(
      "{\"samples\": %zu, \"steps\": %zu, \"distance_m\": %.3f, \"end_x_m\": %.3f, "
      "\"end_y_m\": %.3f, \"heading_deg\": %.2f, \"pose\": 0, \"cadence_spm\": %.1f, "
      "\"gyro_bias_rad_s\": [%.5f, %.5f, %.5f], \"gyro\": %s, \"mag\": %s, "
      "\"repeated_stamps\": %zu, \"ns_per_sample\": %.1f}\n",
      records.size(), f.steps, f.distance_m, f.x_m, f.y_m, f.heading_deg, 60.0 * f.step_hz, b.x(),
      b.y(), b.z(), has_gyro ? "true" : "false", has_mag ? "true" : "false", repeated,
      walk.ns_per_sample);
}

/// The pose-switch counts of the summary (all 0 for a foot: it has no pose).
struct Switches {
  unsigned switches = 0, pose_changes = 0, replaced_headings = 0;
};
Switches switches_of(const fusion::Pdr& pdr) {
  const auto& d = pdr.diagnostics();
  return {d.switches, d.pose_changes, d.replaced_headings};
}
Switches switches_of(const fusion::FootPdr& /*pdr*/) { return {}; }
Switches switches_of(const fusion::TrunkPdr& /*pdr*/) { return {}; }

/// Runs `pdr` (Pdr, FootPdr or TrunkPdr) over the records: the track CSV, one row per step, and the
/// JSON summary. The two print the same columns and fields, so that a foot's track and a phone's
/// read alike: the foot's pose and switch columns are those of a pose that never changes.
template <class Pipeline>
void run_track(const PdrOptions& o, const std::vector<ImuRecord>& records, bool has_gyro,
               bool has_mag, std::size_t repeated, Pipeline& pdr) {
  io::CsvWriter track(o.out, {"t_s", "x_m", "y_m", "heading_deg", "pose", "steps", "distance_m",
                              "step_length_m", "cadence_spm", "switching"});
  auto write = [&track](const fusion::PdrOutput& r) {
    track.row({r.t_s, r.x_m, r.y_m, r.heading_deg, static_cast<double>(r.pose),
               static_cast<double>(r.steps), r.distance_m, r.last_step_length_m, r.cadence_spm,
               r.switching ? 1.0 : 0.0});
  };
  std::chrono::nanoseconds spent{0};
  bool first = true;
  for (const auto& r : records) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto& out = pdr.update(r.imu, r.mag_uT);
    spent += std::chrono::steady_clock::now() - t0;
    if (first || out.step) write(out);
    first = false;
  }
  track.close();
  const auto& f = pdr.output();
  const Switches d = switches_of(pdr);
  std::printf(
      "{\"samples\": %zu, \"steps\": %zu, \"distance_m\": %.3f, \"end_x_m\": %.3f, "
      "\"end_y_m\": %.3f, \"heading_deg\": %.2f, \"pose\": %d, \"cadence_spm\": %.1f, "
      "\"pose_switches\": %u, \"pose_changes\": %u, \"replaced_headings\": %u, \"gyro\": %s, "
      "\"mag\": %s, \"repeated_stamps\": %zu, \"ns_per_sample\": %.1f}\n",
      records.size(), f.steps, f.distance_m, f.x_m, f.y_m, f.heading_deg, static_cast<int>(f.pose),
      f.cadence_spm, d.switches, d.pose_changes, d.replaced_headings, has_gyro ? "true" : "false",
      has_mag ? "true" : "false", repeated,
      static_cast<double>(spent.count()) / static_cast<double>(records.size()));
}

void run_pdr(const PdrOptions& o) {
  if (!(o.height_m > 0.5 && o.height_m < 2.5))
    throw UsageError("--height-m must be a body height in metres (0.5-2.5)");
  if (!(o.step_scale >= 0.5 && o.step_scale <= 1.5))
    throw UsageError("--step-scale must be a personal factor between 0.5 and 1.5");
  if (o.mount != "phone" && o.mount != "body" && o.mount != "foot" && o.mount != "trunk")
    throw UsageError("unknown mount '" + o.mount + "' (phone, body, foot, trunk)");
  bool has_gyro = false, has_mag = false;
  std::size_t repeated = 0;
  const auto records = read_imu_csv(o.in, false, &has_gyro, &has_mag, &repeated);
  if (o.mount == "phone") {
    run_handheld(o, records, has_gyro, has_mag, repeated);
    return;
  }
  if (o.mount == "foot") {
    fusion::FootPdr pdr;  // the stride is measured: no height, no step scale
    run_track(o, records, has_gyro, has_mag, repeated, pdr);
    return;
  }
  if (o.mount == "trunk") {
    fusion::TrunkPdrParams params;  // each step measured by the pendulum: no step scale
    params.height_m = o.height_m;
    auto pdr = std::make_unique<fusion::TrunkPdr>(params);  // 50 kB of rings: not on the stack
    run_track(o, records, has_gyro, has_mag, repeated, *pdr);
    return;
  }
  fusion::PdrParams params;
  params.step_length.height_m = o.height_m;
  params.step_length.scale.fill(o.step_scale);
  fusion::Pdr pdr(params);
  run_track(o, records, has_gyro, has_mag, repeated, pdr);
}

}  // namespace

void register_pdr(CLI::App& app) {
  auto opts = std::make_shared<PdrOptions>();
  auto* cmd = app.add_subcommand(
      "pdr", "Pedestrian dead reckoning (seed 003): track from a phone or foot IMU CSV");
  cmd->add_option("--in", opts->in,
                  "IMU CSV: t_s,ax_m_s2,ay_m_s2,az_m_s2 + optional gx_rad_s.., mx_uT..")
      ->required();
  cmd->add_option("--height-m", opts->height_m, "walker's height, m")->required();
  cmd->add_option("--out", opts->out,
                  "track CSV, one row per step: t_s,x_m (east),y_m (north),heading_deg,pose "
                  "(0 hand-held, 1 call, 2 pocket, 3 arm swing),steps,distance_m,...")
      ->required();
  cmd->add_option("--step-scale", opts->step_scale,
                  "personal step-length factor: known length / distance_m of this command on a "
                  "calibration walk (e.g. 100 m hand-held)")
      ->capture_default_str();
  cmd->add_option("--mount", opts->mount,
                  "phone: held in front (reading pose; steps only while walking, heading from "
                  "the gyro about the vertical; the track re-laid once the walk is over with the "
                  "gyro bias all its stands measured) | body: the four simulated poses of seed "
                  "003 | foot: each stride measured by the foot's inertial navigation, reset at "
                  "every stance (height and step scale unused; a gyro is required) | trunk: a "
                  "belt or lower-back sensor, each step measured from the trunk's rise and fall "
                  "(the inverted pendulum on a leg of 0.53 x height; step scale unused; a gyro is "
                  "required)")
      ->capture_default_str();
  cmd->callback([opts] { run_pdr(*opts); });
}

}  // namespace telltale::cli
