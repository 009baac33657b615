// fusion_cli attitude: IMU.csv -> ATT.csv (SPEC section 6).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "csv.hpp"
#include "telltale/fusion/attitude.hpp"

namespace telltale::cli {
namespace {

struct AttitudeOptions {
  std::string in;
  std::string out;
  std::string filter{fusion::kDefaultAttitudeFilter};
  double gyro_range_dps = 0.0;  // 0: the production filter's default (the boat instrument's)
  double acc_range_g = 0.0;
};

void run_attitude(const AttitudeOptions& o) {
  fusion::SensorRanges ranges;  // what the recording's sensor clips at, where given
  if (o.gyro_range_dps > 0.0) ranges.gyro_rad_s = o.gyro_range_dps * M_PI / 180.0;
  if (o.acc_range_g > 0.0) ranges.acc_m_s2 = o.acc_range_g * fusion::kStandardGravity_m_s2;
  auto filter = fusion::make_attitude_filter(o.filter, Eigen::Vector3d::Zero(), ranges);
  if (!filter)
    throw UsageError("unknown filter '" + o.filter + "' (see fusion_cli attitude --help)");
  io::CsvReader reader(
      o.in,
      {{"t_s"}, {"gx_rad_s"}, {"gy_rad_s"}, {"gz_rad_s"}, {"ax_m_s2"}, {"ay_m_s2"}, {"az_m_s2"}},
      "t_s");
  io::CsvWriter writer(o.out, {"t_s", "heel_deg", "pitch_deg", "heel_rate_deg_s",
                               "pitch_rate_deg_s", "yaw_rate_deg_s", "acc_weight", "quality"});
  std::vector<double> row;
  std::size_t samples = 0;
  std::chrono::nanoseconds in_filter{0};
  constexpr double kDeg = 180.0 / M_PI;
  while (reader.next(row)) {
    fusion::ImuSample s;
    s.t_s = row[0];
    s.gyro_body_rad_s = {row[1], row[2], row[3]};
    s.acc_body_m_s2 = {row[4], row[5], row[6]};
    const auto t0 = std::chrono::steady_clock::now();
    filter->update(s);
    in_filter += std::chrono::steady_clock::now() - t0;
    const fusion::AttitudeOutput a = filter->output();
    writer.row({s.t_s, a.heel_rad * kDeg, a.pitch_rad * kDeg, a.heel_rate_rad_s * kDeg,
                a.pitch_rate_rad_s * kDeg, a.yaw_rate_rad_s * kDeg, a.acc_weight, a.quality});
    ++samples;
  }
  writer.close();
  if (samples == 0) throw io::CsvError(o.in + ":2:0: no data rows");
  std::printf("{\"samples\": %zu, \"ns_per_sample\": %.1f, \"filter\": \"%s\"}\n", samples,
              static_cast<double>(in_filter.count()) / static_cast<double>(samples),
              o.filter.c_str());
}

}  // namespace

void register_attitude(CLI::App& app) {
  auto opts = std::make_shared<AttitudeOptions>();
  std::string filters =
      "filter name (default " + std::string(fusion::kDefaultAttitudeFilter) + "):";
  for (const auto& n : fusion::attitude_filter_names()) {
    filters += "\n  " + n + ": " + fusion::attitude_filter_description(n);
  }
  auto* cmd = app.add_subcommand("attitude", "Heel and pitch from an IMU CSV");
  cmd->add_option("--in", opts->in,
                  "IMU CSV: t_s,gx_rad_s,gy_rad_s,gz_rad_s,ax_m_s2,ay_m_s2,az_m_s2")
      ->required();
  cmd->add_option("--out", opts->out,
                  "output CSV: t_s,heel_deg,pitch_deg,heel_rate_deg_s,pitch_rate_deg_s,"
                  "yaw_rate_deg_s,acc_weight,quality")
      ->required();
  cmd->add_option("--filter", opts->filter, filters);
  cmd->add_option("--gyro-range-dps", opts->gyro_range_dps,
                  "the recording's gyro full scale, deg/s (a reading at 98 % of it is taken for "
                  "clipped; default: the boat instrument's 250)")
      ->check(CLI::Range(1.0, 100000.0));
  cmd->add_option("--acc-range-g", opts->acc_range_g,
                  "the recording's accelerometer full scale, g (default: the boat instrument's 2)")
      ->check(CLI::Range(0.1, 1000.0));
  cmd->callback([opts] { run_attitude(*opts); });
}

}  // namespace telltale::cli
