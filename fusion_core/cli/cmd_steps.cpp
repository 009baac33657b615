// fusion_cli steps: IMU.csv -> step count and times as JSON (SPEC section 6).
#include <cstdio>
#include <ranges>
#include <string>

#include "commands.hpp"
#include "gait_io.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::cli {
namespace {

struct StepsOptions {
  std::string in;
  std::string method;
  std::string mount = "foot";
};

fusion::StepMount parse_mount(const std::string& m) {
  if (m == "foot") return fusion::StepMount::kFoot;
  if (m == "body" || m == "phone") return fusion::StepMount::kBody;
  throw UsageError("unknown mount '" + m + "' (foot, body, phone)");
}

void run_steps(const StepsOptions& o) {
  const auto mount = parse_mount(o.mount);
  // A belt or lower-back sensor (--mount body) is rigid to the trunk, whose vertical oscillation
  // gait-phase counts from the first step to the last; a phone (--mount phone) may be in a hand,
  // a bag or a swinging arm, where peak-valley holds (Oxford traces).
  const std::string method = !o.method.empty() ? o.method
                             : o.mount == "body"
                                 ? std::string("gait-phase")
                                 : std::string(fusion::default_step_detector(mount));
  auto detector = fusion::make_step_detector(method, mount);
  if (!detector) throw UsageError("unknown step method '" + method + "'");
  std::size_t repeated = 0;
  const auto records = read_imu_csv(o.in, false, nullptr, nullptr, &repeated);
  std::string times;
  std::size_t steps = 0;
  const auto add = [&](const fusion::StepEvent& ev) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.3f", steps ? ", " : "", ev.t_s);
    times += buf;
    ++steps;
  };
  fusion::for_each_step(*detector, records | std::views::transform(&ImuRecord::imu), add);
  // repeated_stamps: rows whose time stamp repeated the previous row's, merged into it (their
  // mean: see read_imu_csv); samples: the records after merging; refused_handling: candidate
  // steps not counted because the phone was being handled (peak-valley's tilt rule).
  std::printf(
      "{\"steps\": %zu, \"step_times_s\": [%s], \"method\": \"%s\", \"mount\": \"%s\", "
      "\"samples\": %zu, \"repeated_stamps\": %zu, \"refused_handling\": %u}\n",
      steps, times.c_str(), method.c_str(), o.mount.c_str(), records.size(), repeated,
      detector->diagnostics().rejected_handling);
}

}  // namespace

void register_steps(CLI::App& app) {
  auto opts = std::make_shared<StepsOptions>();
  std::string names;
  for (auto n : fusion::step_detector_names())
    names += std::string(names.empty() ? "" : ", ") + std::string(n);
  auto* cmd = app.add_subcommand("steps", "Count steps in an IMU CSV (gyro columns optional)");
  cmd->add_option("--in", opts->in,
                  "IMU CSV: t_s,ax_m_s2,ay_m_s2,az_m_s2[,gx_rad_s,gy_rad_s,gz_rad_s]")
      ->required();
  cmd->add_option(
      "--method", opts->method,
      "detector: " + names + " (default: gait-phase for foot and body, peak-valley for phone)");
  cmd->add_option("--mount", opts->mount, "foot (counts that foot's steps) | body | phone")
      ->capture_default_str();
  cmd->callback([opts] { run_steps(*opts); });
  register_pdr(app);
}

}  // namespace telltale::cli
