// fusion_cli gait-sim: the gait simulator's scenarios to CSV (IMU + truth).
#include <cstdio>
#include <string>

#include "commands.hpp"
#include "gait_io.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::cli {
namespace {

struct GaitSimOptions {
  std::string scenario;
  std::uint64_t seed = 1;
  std::string out;
  std::string truth;
};

void run_gait_sim(const GaitSimOptions& o) {
  const auto sc = fusion::sim::make_gait_scenario(o.scenario, o.seed);
  if (!sc) throw UsageError("unknown gait scenario '" + o.scenario + "'");
  const fusion::sim::Person person = fusion::sim::random_person(o.seed);
  const auto run = fusion::sim::simulate_gait(*sc, person, o.seed);
  write_gait_run(run, o.out, o.truth);
  std::printf(
      "{\"scenario\": \"%s\", \"seed\": %llu, \"samples\": %zu, \"steps\": %zu, "
      "\"foot_steps\": %zu, \"distance_m\": %.3f, \"height_m\": %.3f}\n",
      o.scenario.c_str(), static_cast<unsigned long long>(o.seed), run.samples.size(),
      run.step_times_s.size(), run.foot_step_times_s.size(), run.distance_m, person.height_m);
}

}  // namespace

void register_gait_sim(CLI::App& app) {
  auto opts = std::make_shared<GaitSimOptions>();
  std::string examples;
  for (const auto& e : fusion::sim::gait_scenario_examples()) examples += " " + e;
  auto* cmd = app.add_subcommand(
      "gait-sim",
      "Simulated walker with a foot-mounted IMU or a phone, with truth. SCENARIO: foot-GAIT, "
      "body-GAIT, phone-POSE-GAIT, *-mixed, phone-switch, loop; GAIT slow-walk|walk|fast-walk|"
      "jog|run, POSE hand-held|call|pocket|arm-swing. e.g." +
          examples);
  cmd->add_option("scenario", opts->scenario, "scenario name")->required();
  cmd->add_option("--seed", opts->seed, "seed: the person, the noise, the loop geometry")
      ->capture_default_str();
  cmd->add_option("--out", opts->out, "IMU CSV (t_s, gyro, acc, mag)")->required();
  cmd->add_option("--truth", opts->truth, "truth CSV (position, heading, gait, pose, steps)");
  cmd->callback([opts] { run_gait_sim(*opts); });
}

}  // namespace telltale::cli
