// fusion_cli simulate SCENARIO --seed N --out IMU.csv --truth TRUTH.csv [--rate-hz R]
#include <cmath>
#include <string>

#include "commands.hpp"
#include "csv.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::cli {
namespace {

struct SimulateOptions {
  std::string scenario;
  std::uint64_t seed = 1;
  std::string out;
  std::string truth;
  double rate_hz = 25.0;
  double duration_s = 0.0;
};

void run_simulate(const SimulateOptions& o) {
  const double duration =
      o.duration_s > 0.0 ? o.duration_s : fusion::sim::scenario_default_duration_s(o.scenario);
  auto sc = fusion::sim::make_scenario(o.scenario, o.seed, o.rate_hz, duration);
  if (!sc) throw UsageError("unknown scenario '" + o.scenario + "' or bad --rate-hz");
  io::CsvWriter imu_out(
      o.out, {"t_s", "gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2", "az_m_s2"});
  io::CsvWriter truth_out(o.truth, {"t_s", "heel_deg", "pitch_deg", "yaw_deg", "heel_rate_deg_s",
                                    "pitch_rate_deg_s", "scored"});
  constexpr double kDeg = 180.0 / M_PI;
  fusion::ImuSample s;
  fusion::sim::AttitudeTruth t;
  while (sc->next(s, t)) {
    imu_out.row({s.t_s, s.gyro_body_rad_s.x(), s.gyro_body_rad_s.y(), s.gyro_body_rad_s.z(),
                 s.acc_body_m_s2.x(), s.acc_body_m_s2.y(), s.acc_body_m_s2.z()});
    truth_out.row({t.t_s, t.heel_rad * kDeg, t.pitch_rad * kDeg, t.yaw_rad * kDeg,
                   t.heel_rate_rad_s * kDeg, t.pitch_rate_rad_s * kDeg,
                   t.t_s >= sc->warmup_s() ? 1.0 : 0.0});
  }
  imu_out.close();
  truth_out.close();
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto opts = std::make_shared<SimulateOptions>();
  std::string names = "scenario:";
  for (const auto& n : fusion::sim::scenario_names()) names += " " + n;
  auto* cmd =
      app.add_subcommand("simulate", "Simulated IMU CSV and its truth (scenarios of the tests)");
  cmd->add_option("scenario", opts->scenario, names)->required();
  cmd->add_option("--seed", opts->seed, "random seed")->capture_default_str();
  cmd->add_option("--out", opts->out, "IMU CSV: t_s,gx_rad_s,...,az_m_s2")->required();
  cmd->add_option("--truth", opts->truth,
                  "truth CSV: t_s,heel_deg,pitch_deg,yaw_deg,heel_rate_deg_s,pitch_rate_deg_s,"
                  "scored (0 during the start-up rest)")
      ->required();
  cmd->add_option("--rate-hz", opts->rate_hz, "sample rate")->capture_default_str();
  cmd->add_option("--duration-s", opts->duration_s, "length (default: the scenario's)");
  cmd->callback([opts] { run_simulate(*opts); });
}

}  // namespace telltale::cli
