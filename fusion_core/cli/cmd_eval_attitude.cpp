// fusion_cli eval attitude: scenario x filter heel/pitch errors over seeds, and the BROAD
// recordings' inclination RMSE for every filter.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "broad.hpp"
#include "commands.hpp"
#include "csv.hpp"
#include "telltale/fusion/attitude_eval.hpp"
#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::cli {
namespace {

struct EvalAttitudeOptions {
  int seeds = 10;
  std::vector<double> rates_hz{25.0, 100.0};
  std::vector<std::string> filters;    // empty = all
  std::vector<std::string> scenarios;  // empty = all
  std::string broad_dir;               // empty = broad/ in the real-data folder
  std::string data_dir;                // --data: the real-data folder (real_data_dir)
  bool skip_broad = false;
  double broad_rate_hz = 0.0;  // > 0: BROAD resampled to this rate (fusion::resample_trial)
  bool skip_sim = false;
  bool uncalibrated = false;  ///< raw datasheet sensor errors instead of the calibrated instrument
};

bool progress_enabled() { return isatty(fileno(stderr)) != 0; }

void progress(const std::string& what) {
  if (progress_enabled()) std::fprintf(stderr, "\r\033[K%s", what.c_str());
}
void progress_done() {
  if (progress_enabled()) std::fprintf(stderr, "\r\033[K");
}

/// --broad-dir, else broad/ in the real-data folder (real_data_dir), else none.
std::string find_broad_dir(const EvalAttitudeOptions& o) {
  if (!o.broad_dir.empty()) return o.broad_dir;
  const std::string d = real_data_dir(o.data_dir) + "/broad";
  return std::filesystem::is_directory(d) ? d : std::string();
}

/// One markdown table: a row per BROAD trial, a column per name, rmse(trial index, name) in
/// each cell, and the columns' means.
void broad_table(const std::vector<std::string>& trials, const std::vector<std::string>& columns,
                 const std::function<double(std::size_t, const std::string&)>& rmse) {
  std::printf("| trial |");
  for (const auto& c : columns) std::printf(" %s |", c.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < columns.size(); ++i) std::printf("---|");
  std::printf("\n");
  std::vector<double> sum(columns.size(), 0.0);
  for (std::size_t t = 0; t < trials.size(); ++t) {
    progress("eval attitude: BROAD " + trials[t]);
    std::printf("| %s |", trials[t].c_str());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const double e = rmse(t, columns[i]);
      sum[i] += e;
      std::printf(" %.2f |", e);
    }
    progress_done();
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf("| **mean** |");
  for (const double s : sum)
    std::printf(" **%.2f** |", trials.empty() ? 0.0 : s / static_cast<double>(trials.size()));
  std::printf("\n");
}

void run_eval_attitude(const EvalAttitudeOptions& o) {
  const std::vector<std::string> filters =
      o.filters.empty() ? fusion::attitude_filter_names() : o.filters;
  const std::vector<std::string> scenarios =
      o.scenarios.empty() ? fusion::sim::scenario_names() : o.scenarios;
  if (!o.broad_dir.empty() && !std::filesystem::is_directory(o.broad_dir)) {
    throw UsageError("--broad-dir '" + o.broad_dir + "' is not a directory");
  }
  for (const auto& f : filters) {
    if (!fusion::make_attitude_filter(f)) throw UsageError("unknown filter '" + f + "'");
  }
  for (const auto& s : scenarios) {
    if (!fusion::sim::make_scenario(s, 1, 25.0, 1.0))
      throw UsageError("unknown scenario '" + s + "'");
  }
  const fusion::sim::ImuErrorParams raw = fusion::sim::ImuErrorParams::uncalibrated();
  for (const double rate : o.skip_sim ? std::vector<double>{} : o.rates_hz) {
    std::printf(
        "\n## attitude: simulator (%s sensors), %d seeds, %.0f Hz: heel RMS, pitch RMS (heel max, "
        "pitch max), deg\n\n",
        o.uncalibrated ? "uncalibrated" : "calibrated", o.seeds, rate);
    std::printf("| scenario |");
    for (const auto& f : filters) std::printf(" %s |", f.c_str());
    std::printf("\n|---|");
    for (std::size_t i = 0; i < filters.size(); ++i) std::printf("---|");
    std::printf("\n");
    for (const auto& sc : scenarios) {
      std::vector<fusion::TiltErrorStats> total(filters.size());
      for (int seed = 1; seed <= o.seeds; ++seed) {
        progress("eval attitude: " + sc + " seed " + std::to_string(seed) + " at " +
                 std::to_string(static_cast<int>(rate)) + " Hz");
        const auto st = fusion::evaluate_on_scenario(filters, sc, static_cast<std::uint64_t>(seed),
                                                     rate, 0.0, o.uncalibrated ? &raw : nullptr);
        for (std::size_t i = 0; i < filters.size(); ++i) total[i].merge(st[i]);
      }
      progress_done();
      std::printf("| %s |", sc.c_str());
      for (const auto& t : total) {
        std::printf(" %.2f, %.2f (%.2f, %.2f) |", t.heel_rms_deg, t.pitch_rms_deg, t.heel_max_deg,
                    t.pitch_max_deg);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  if (o.skip_broad) return;
  const std::string dir = find_broad_dir(o);
  if (dir.empty()) {
    std::printf("\n(BROAD recordings not found: pass --data DIR or --broad-dir DIR)\n");
    return;
  }
  std::vector<std::string> trials;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    const std::string suffix = ".imu.csv";
    if (name.size() > suffix.size() && name.ends_with(suffix)) {
      trials.push_back(name.substr(0, name.size() - suffix.size()));
    }
  }
  std::sort(trials.begin(), trials.end());
  const std::string rate =
      o.broad_rate_hz > 0.0
          ? ", resampled to " + std::to_string(std::lround(o.broad_rate_hz)) + " Hz"
          : "";
  std::vector<fusion::InclinationTrial> data;
  for (const auto& trial : trials) {
    progress("eval attitude: reading BROAD " + trial);
    data.push_back(fusion::resample_trial(
        io::read_broad_trial(dir + "/" + trial + ".imu.csv", dir + "/" + trial + ".truth.csv"),
        o.broad_rate_hz));
  }
  progress_done();
  // As recorded: every trial begins with the sensor at rest for 27-49 s.
  std::printf("\n## attitude: BROAD (%s%s), inclination RMSE over movement rows, deg\n\n",
              dir.c_str(), rate.c_str());
  // Every filter told the recording's sensor's full scales (InclinationTrial::sensor).
  broad_table(trials, filters, [&](std::size_t t, const std::string& f) {
    auto filter = fusion::make_attitude_filter(f, Eigen::Vector3d::Zero(), data[t].sensor);
    return fusion::inclination_rmse_deg(*filter, data[t]);
  });
  // Started in motion: each filter's first sample is the trial's first movement row, so
  // nothing is learnt at the rest before it (a phone picked up, a node started under way).
  // Beside them the production filter restarted there with what it had learnt before (its
  // calibration, TelltaleAttitudeFilter::warm_start, as a boat node keeps it across a restart).
  const bool restart = std::find(filters.begin(), filters.end(), "telltale") != filters.end();
  std::vector<std::string> columns = filters;
  if (restart) columns.emplace_back("telltale restarted");
  std::printf(
      "\n## attitude: BROAD (%s%s) started in motion (at each trial's first movement row), "
      "inclination RMSE over movement rows, deg\n\n",
      dir.c_str(), rate.c_str());
  broad_table(trials, columns, [&](std::size_t t, const std::string& f) {
    const std::size_t from = fusion::first_scored(data[t]);
    const fusion::InclinationTrial moving = fusion::trial_from(data[t], from);
    if (f != "telltale restarted") {
      auto filter = fusion::make_attitude_filter(f, Eigen::Vector3d::Zero(), moving.sensor);
      return fusion::inclination_rmse_deg(*filter, moving);
    }
    const fusion::TelltaleAttitudeParams params = fusion::with_ranges({}, moving.sensor);
    fusion::TelltaleAttitudeFilter before(params);
    for (std::size_t i = 0; i < from; ++i) before.update(data[t].imu[i]);
    fusion::TelltaleAttitudeFilter after(params);
    after.warm_start(before.calibration(), 0.0);
    return fusion::inclination_rmse_deg(after, moving);
  });
}

}  // namespace

void register_eval_attitude(CLI::App& eval, std::vector<std::function<void()>>& run_all) {
  auto opts = std::make_shared<EvalAttitudeOptions>();
  auto* cmd = eval.add_subcommand("attitude",
                                  "heel/pitch: scenario x filter errors, BROAD inclination RMSE");
  cmd->add_option("--seeds", opts->seeds, "simulator seeds per scenario")->capture_default_str();
  cmd->add_option("--rate-hz", opts->rates_hz, "sample rates")->capture_default_str();
  cmd->add_option("--filters", opts->filters, "filters (default: all)");
  cmd->add_option("--scenarios", opts->scenarios, "scenarios (default: all)");
  cmd->add_option("--data", opts->data_dir,
                  "real recordings folder (default: $TELLTALE_DATA, else ../shared/data); "
                  "BROAD is its broad/");
  cmd->add_option("--broad-dir", opts->broad_dir, "BROAD CSV folder (default: DATA/broad)");
  cmd->add_option("--broad-rate-hz", opts->broad_rate_hz,
                  "BROAD resampled to this rate first (averaged over each interval, as a "
                  "sensor's output rate; the recordings are 286 Hz, a boat node runs 25-100 Hz)")
      ->check(CLI::Range(5.0, 1000.0));
  cmd->add_flag("--no-broad", opts->skip_broad, "skip the BROAD recordings");
  cmd->add_flag("--no-sim", opts->skip_sim, "skip the simulator (BROAD only)");
  cmd->add_flag("--uncalibrated", opts->uncalibrated,
                "simulate the sensors with raw datasheet errors (no instrument calibration)");
  cmd->callback([opts] { run_eval_attitude(*opts); });
  run_all.push_back([opts] { run_eval_attitude(*opts); });
}

}  // namespace telltale::cli
