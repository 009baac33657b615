// fusion_cli steps-eval: the accuracy tables of issue 5 (simulated gaits x methods, Oxford phone
// traces, pose classification on held-out people, PDR closed loops).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gait_io.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::cli {
namespace {

namespace sim = fusion::sim;

struct EvalOptions {
  int people = 10;
  std::string oxford_dir;
  std::string tables = "gait,oxford";
};

double count_accuracy(std::size_t counted, std::size_t truth) {
  if (truth == 0) return counted == 0 ? 1.0 : 0.0;
  return 1.0 - std::abs(static_cast<double>(counted) - static_cast<double>(truth)) /
                   static_cast<double>(truth);
}

std::size_t count_steps(fusion::StepDetector& d, const std::vector<fusion::ImuSample>& samples) {
  d.reset();
  std::size_t n = 0;
  fusion::StepEvent ev;
  for (const auto& s : samples) n += d.update(s, ev) ? 1u : 0u;
  return n;
}

void progress(const char* what, int i, int n) {
  if (isatty(2)) std::fprintf(stderr, "\r%s %d/%d", what, i, n);
  if (isatty(2) && i == n) std::fprintf(stderr, "\n");
}

void gait_table(const EvalOptions& o) {
  const auto names = fusion::step_detector_names();
  for (const std::string site : {"foot", "body"}) {
    const auto mount = site == "foot" ? fusion::StepMount::kFoot : fusion::StepMount::kBody;
    std::printf("\n## Step count accuracy, %s-mounted sensor, %d simulated people "
                "(mean / worst person, %%)\n\n| gait |",
                site.c_str(), o.people);
    for (auto n : names) std::printf(" %.*s |", static_cast<int>(n.size()), n.data());
    std::printf("\n|---|");
    for (std::size_t i = 0; i < names.size(); ++i) std::printf("---|");
    std::printf("\n");
    std::vector<std::string> gaits;
    for (int g = 0; g < sim::kGaitCount; ++g) gaits.emplace_back(sim::gait_name(static_cast<sim::Gait>(g)));
    gaits.emplace_back("mixed");
    for (const auto& g : gaits) {
      std::vector<double> sum(names.size(), 0.0), worst(names.size(), 1.0);
      for (int p = 0; p < o.people; ++p) {
        const auto seed = static_cast<std::uint64_t>(p + 1);
        const auto sc = sim::make_gait_scenario(site + "-" + g, seed);
        const auto run = sim::simulate_gait(*sc, sim::random_person(seed), seed);
        std::vector<fusion::ImuSample> samples;
        for (const auto& s : run.samples) samples.push_back(s.imu);
        const std::size_t truth =
            site == "foot" ? run.foot_step_times_s.size() : run.step_times_s.size();
        for (std::size_t m = 0; m < names.size(); ++m) {
          auto d = fusion::make_step_detector(names[m], mount);
          const double acc = count_accuracy(count_steps(*d, samples), truth);
          sum[m] += acc;
          worst[m] = std::min(worst[m], acc);
        }
      }
      std::printf("| %s |", g.c_str());
      for (std::size_t m = 0; m < names.size(); ++m)
        std::printf(" %.1f / %.1f |", 100.0 * sum[m] / o.people, 100.0 * worst[m]);
      std::printf("\n");
      std::fflush(stdout);
    }
  }
}

std::string find_oxford(const std::string& given) {
  if (!given.empty()) return given;
  for (const char* d : {"../shared/data/oxford_steps", "/work/shared/data/oxford_steps",
                        "tests/data/oxford_steps"})
    if (std::filesystem::exists(std::string(d) + "/counts.csv")) return d;
  throw UsageError("no Oxford traces found: give --oxford DIR");
}

void oxford_table(const EvalOptions& o) {
  const std::string dir = find_oxford(o.oxford_dir);
  std::ifstream counts(dir + "/counts.csv");
  std::string line;
  std::getline(counts, line);  // header: trace,position,steps
  std::vector<std::pair<std::string, int>> traces;
  while (std::getline(counts, line)) {
    const auto c1 = line.find(','), c2 = line.rfind(',');
    if (c1 == std::string::npos || c2 == c1) continue;
    traces.emplace_back(line.substr(0, c1), std::stoi(line.substr(c2 + 1)));
  }
  const auto names = fusion::step_detector_names();
  std::printf("\n## Oxford phone traces (%s): count accuracy per trace, %%\n\n| trace | true |",
              dir.c_str());
  for (auto n : names) std::printf(" %.*s |", static_cast<int>(n.size()), n.data());
  std::printf("\n|---|---|");
  for (std::size_t i = 0; i < names.size(); ++i) std::printf("---|");
  std::printf("\n");
  std::vector<double> sum(names.size(), 0.0);
  int i = 0;
  for (const auto& [trace, truth] : traces) {
    progress("oxford", ++i, static_cast<int>(traces.size()));
    std::string path = dir + "/" + trace + ".imu.csv";
    if (!std::filesystem::exists(path)) path += ".gz";
    const auto records = read_imu_csv(path, false);
    std::vector<fusion::ImuSample> samples;
    for (const auto& r : records) samples.push_back(r.imu);
    std::printf("| %s | %d |", trace.c_str(), truth);
    for (std::size_t m = 0; m < names.size(); ++m) {
      auto d = fusion::make_step_detector(names[m], fusion::StepMount::kBody);
      const std::size_t n = count_steps(*d, samples);
      const double acc = count_accuracy(n, static_cast<std::size_t>(truth));
      sum[m] += acc;
      std::printf(" %zu (%.1f) |", n, 100.0 * acc);
    }
    std::printf("\n");
  }
  std::printf("| **mean** | |");
  for (std::size_t m = 0; m < names.size(); ++m)
    std::printf(" **%.2f** |", 100.0 * sum[m] / static_cast<double>(traces.size()));
  std::printf("\n");
}

void run_eval(const EvalOptions& o) {
  if (o.tables.find("gait") != std::string::npos) gait_table(o);
  if (o.tables.find("oxford") != std::string::npos) oxford_table(o);
}

}  // namespace

void register_steps_eval(CLI::App& app) {
  auto opts = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand("steps-eval", "Accuracy tables: gaits x step methods, Oxford "
                                               "traces, pose classifier, PDR closed loops");
  cmd->add_option("--people", opts->people, "simulated people per gait")->capture_default_str();
  cmd->add_option("--oxford", opts->oxford_dir,
                  "Oxford step traces (default: ../shared/data/oxford_steps, then "
                  "tests/data/oxford_steps)");
  cmd->add_option("--tables", opts->tables, "comma list: gait, oxford, pose, pdr")
      ->capture_default_str();
  cmd->callback([opts] { run_eval(*opts); });
}

}  // namespace telltale::cli
