// fusion_cli heading | heading-sim | heading-eval: redundant heading sensors (SPEC section 6).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "csv.hpp"
#include "telltale/fusion/heading_fusion.hpp"
#include "telltale/fusion/sim/heading_eval.hpp"
#include "telltale/fusion/sim/heading_sim.hpp"

namespace telltale::cli {
namespace {

using fusion::HeadingFusion;
using fusion::HeadingFusionParams;
using fusion::HeadingMethod;
using fusion::kMaxHeadingSensors;

std::string method_list() {
  std::string s;
  for (HeadingMethod m : fusion::kAllHeadingMethods) {
    if (!s.empty()) s += ", ";
    s += std::string(fusion::heading_method_name(m));
  }
  return s;
}

HeadingMethod method_or_throw(const std::string& name) {
  const auto m = fusion::heading_method_from_name(name);
  if (!m) throw UsageError("unknown method '" + name + "' (known: " + method_list() + ")");
  return *m;
}

/// "0.1,0.2,0.5" -> values; one value applies to every sensor.
void apply_per_sensor(const std::vector<double>& v, const char* what, int n,
                      std::array<double, kMaxHeadingSensors>& out) {
  if (v.empty()) return;
  if (v.size() != 1 && static_cast<int>(v.size()) != n) {
    throw UsageError(std::string(what) + ": give one value or one per sensor (" +
                     std::to_string(n) + ")");
  }
  for (int i = 0; i < n; ++i) {
    const double x = v.size() == 1 ? v[0] : v[static_cast<std::size_t>(i)];
    if (!std::isfinite(x) || x < 0.0) throw UsageError(std::string(what) + ": must be >= 0");
    out[static_cast<std::size_t>(i)] = x;
  }
}

// ------------------------------------------------------------------------- heading

struct HeadingOptions {
  std::string in;
  std::string out;
  std::string method = "closed-loop";
  std::vector<double> noise_deg;
  std::vector<double> latency_s;
  double accel_var = HeadingFusionParams{}.accel_var_deg2_s4;
  bool paper = false;
  bool no_fault_detection = false;
};

void run_heading(const HeadingOptions& o) {
  std::vector<io::CsvColumn> cols{{"t_s"}};
  for (int i = 1; i <= kMaxHeadingSensors; ++i) {
    cols.push_back({"h" + std::to_string(i) + "_deg", i == 1, true});
  }
  io::CsvReader reader(o.in, cols, "t_s");
  int n = 0;
  while (n < kMaxHeadingSensors && reader.has_column("h" + std::to_string(n + 1) + "_deg")) ++n;
  for (int i = n + 1; i <= kMaxHeadingSensors; ++i) {
    if (reader.has_column("h" + std::to_string(i) + "_deg")) {
      throw io::CsvError(o.in + ":1:0: sensor columns must be h1_deg..hN_deg without gaps (h" +
                         std::to_string(n + 1) + "_deg missing)");
    }
  }
  HeadingFusionParams p = o.paper ? HeadingFusionParams::paper() : HeadingFusionParams{};
  p.sensor_count = n;
  p.method = method_or_throw(o.method);
  if (!o.paper) p.accel_var_deg2_s4 = o.accel_var;
  if (!(p.accel_var_deg2_s4 > 0.0)) throw UsageError("--accel-var must be > 0");
  apply_per_sensor(o.noise_deg, "--noise-deg", n, p.noise_deg);
  apply_per_sensor(o.latency_s, "--latency-s", n, p.latency_s);
  p.monitor.enabled = !o.no_fault_detection;

  io::CsvWriter writer(o.out, {"t_s", "heading_deg", "rate_deg_s", "heading_sd_deg",
                               "sensors_in_use", "sensors_excluded", "model_mismatch"});
  HeadingFusion f(p);
  std::vector<double> row;
  std::array<double, kMaxHeadingSensors> y{};
  std::size_t samples = 0;
  std::chrono::nanoseconds in_filter{0};
  std::uint64_t excluded_steps = 0;
  while (reader.next(row)) {
    for (int i = 0; i < n; ++i)
      y[static_cast<std::size_t>(i)] = row[static_cast<std::size_t>(i + 1)];
    const auto t0 = std::chrono::steady_clock::now();
    f.update(row[0], y.data());
    in_filter += std::chrono::steady_clock::now() - t0;
    ++samples;
    const auto& d = f.diagnostics();
    excluded_steps += d.sensors_excluded != 0 ? 1 : 0;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    writer.row({row[0], f.initialised() ? f.heading_deg() : nan,
                f.initialised() ? f.rate_deg_s() : nan, std::sqrt(f.heading_var_deg2()),
                static_cast<double>(d.sensors_in_use), static_cast<double>(d.sensors_excluded),
                d.model_mismatch ? 1.0 : 0.0});
  }
  writer.close();
  if (samples == 0) throw io::CsvError(o.in + ":2:0: no data rows");
  const auto& d = f.diagnostics();
  std::printf(
      "{\"samples\": %zu, \"sensors\": %d, \"method\": \"%s\", \"ns_per_sample\": %.1f, "
      "\"exclusions\": %llu, \"steps_with_excluded_sensor\": %llu, \"model_mismatches\": %llu, "
      "\"rejected_time\": %llu, \"rejected_non_finite\": %llu}\n",
      samples, n, o.method.c_str(),
      static_cast<double>(in_filter.count()) / static_cast<double>(samples),
      static_cast<unsigned long long>(d.exclusions),
      static_cast<unsigned long long>(excluded_steps),
      static_cast<unsigned long long>(d.model_mismatches),
      static_cast<unsigned long long>(d.rejected_time),
      static_cast<unsigned long long>(d.rejected_non_finite));
}

// ------------------------------------------------------------------------- heading-sim

struct SimOptions {
  std::string scenario;
  std::uint64_t seed = 1;
  std::string out;
  std::string truth;
};

fusion::sim::HeadingScenario scenario_or_throw(const std::string& name) {
  const auto sc = fusion::sim::heading_scenario(name);
  if (!sc) {
    std::string known;
    for (auto s : fusion::sim::heading_scenario_names())
      known += (known.empty() ? "" : ", ") + std::string(s);
    throw UsageError("unknown heading scenario '" + name + "' (known: " + known + ")");
  }
  return *sc;
}

void run_heading_sim(const SimOptions& o) {
  const auto sc = scenario_or_throw(o.scenario);
  const auto samples = fusion::sim::simulate_heading(sc, o.seed);
  const std::size_t n = sc.sensors.size();
  std::vector<std::string> header{"t_s"};
  for (std::size_t i = 1; i <= n; ++i) header.push_back("h" + std::to_string(i) + "_deg");
  io::CsvWriter out(o.out, header);
  std::vector<std::string> th{"t_s", "heading_deg", "rate_deg_s"};
  for (std::size_t i = 1; i <= n; ++i) th.push_back("fault" + std::to_string(i));
  std::unique_ptr<io::CsvWriter> truth;
  if (!o.truth.empty()) truth = std::make_unique<io::CsvWriter>(o.truth, th);
  std::vector<double> row;
  for (const auto& s : samples) {
    row.assign(1, s.t_s);
    row.insert(row.end(), s.reading_deg.begin(), s.reading_deg.end());
    out.row(row);
    if (truth) {
      row = {s.t_s, s.truth_heading_deg, s.truth_rate_deg_s};
      for (std::size_t i = 0; i < n; ++i) {
        row.push_back(fusion::sim::heading_fault_active(sc, static_cast<int>(i), s.t_s) ? 1.0
                                                                                        : 0.0);
      }
      truth->row(row);
    }
  }
  out.close();
  if (truth) truth->close();
  std::printf("{\"scenario\": \"%s\", \"seed\": %llu, \"samples\": %zu, \"sensors\": %zu}\n",
              o.scenario.c_str(), static_cast<unsigned long long>(o.seed), samples.size(), n);
}

// ------------------------------------------------------------------------- heading-eval

struct EvalOptions {
  std::vector<std::string> scenarios;
  std::vector<std::string> methods;
  int seeds = 5;
};

std::string fmt(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

void run_heading_eval(const EvalOptions& o) {
  std::vector<std::string> scenarios = o.scenarios;
  if (scenarios.empty()) {
    for (auto s : fusion::sim::heading_scenario_names()) scenarios.emplace_back(s);
  }
  std::vector<HeadingMethod> methods;
  if (o.methods.empty()) {
    methods.assign(fusion::kAllHeadingMethods.begin(), fusion::kAllHeadingMethods.end());
  } else {
    for (const auto& m : o.methods) methods.push_back(method_or_throw(m));
  }
  if (o.seeds < 1 || o.seeds > 1000) throw UsageError("--seeds must be 1..1000");
  std::printf(
      "| scenario | method | RMS deg (mean) | RMS deg (worst) | max err deg | mean NEES | "
      "isolated after s (worst) | re-admitted after s (worst) | false exclusions |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& name : scenarios) {
    const auto sc = scenario_or_throw(name);
    std::vector<std::vector<fusion::sim::HeadingSimSample>> runs;
    for (int s = 1; s <= o.seeds; ++s) {
      runs.push_back(fusion::sim::simulate_heading(sc, static_cast<std::uint64_t>(s)));
    }
    for (HeadingMethod m : methods) {
      HeadingFusionParams p = sc.fusion;
      p.method = m;
      double rms_sum = 0.0;
      double rms_worst = 0.0;
      double max_err = 0.0;
      double nees = 0.0;
      double iso = sc.faults.empty() ? std::numeric_limits<double>::quiet_NaN() : 0.0;
      double readmit = iso;
      bool never_iso = false;
      bool never_back = false;
      std::uint64_t false_ex = 0;
      for (const auto& samples : runs) {
        const auto r = fusion::sim::run_heading(sc, samples, p);
        rms_sum += r.rms_deg;
        rms_worst = std::max(rms_worst, r.rms_deg);
        max_err = std::max(max_err, r.max_err_deg);
        nees += r.mean_nees;
        if (sc.faults.empty()) false_ex += r.exclusions;
        for (const auto& f : r.faults) {
          if (f.isolation_s < 0) never_iso = true;
          iso = std::max(iso, f.isolation_s);
          const bool recovers =
              sc.faults[static_cast<std::size_t>(&f - r.faults.data())].t_end_s < sc.duration_s;
          if (recovers && f.readmit_s < 0) never_back = true;
          if (recovers) readmit = std::max(readmit, f.readmit_s);
        }
      }
      const double k = static_cast<double>(runs.size());
      std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", name.c_str(),
                  std::string(fusion::heading_method_name(m)).c_str(), fmt(rms_sum / k, 3).c_str(),
                  fmt(rms_worst, 3).c_str(), fmt(max_err, 2).c_str(), fmt(nees / k, 2).c_str(),
                  never_iso ? "never" : fmt(iso, 1).c_str(),
                  never_back ? "never" : fmt(readmit, 1).c_str(),
                  sc.faults.empty() ? std::to_string(false_ex).c_str() : "-");
    }
  }
}

}  // namespace

void register_heading(CLI::App& app) {
  {
    auto o = std::make_shared<HeadingOptions>();
    auto* cmd = app.add_subcommand("heading", "Fuse N heading sensors: H.csv -> F.csv");
    cmd->add_option("--in", o->in,
                    "H.csv: t_s,h1_deg,...,hN_deg (N <= 8; empty or nan = no reading)")
        ->required();
    cmd->add_option("--out", o->out,
                    "F.csv: t_s,heading_deg,rate_deg_s,heading_sd_deg,sensors_in_use,"
                    "sensors_excluded,model_mismatch (bit i = sensor i+1)")
        ->required();
    cmd->add_option("--method", o->method, "fusion method: " + method_list())
        ->capture_default_str();
    cmd->add_option("--noise-deg", o->noise_deg, "sensor noise sigma, deg (one, or one per sensor)")
        ->delimiter(',');
    cmd->add_option("--latency-s", o->latency_s, "sensor latency, s (one, or one per sensor)")
        ->delimiter(',');
    cmd->add_option("--accel-var", o->accel_var, "Q: yaw acceleration variance, (deg/s^2)^2")
        ->capture_default_str();
    cmd->add_flag("--paper", o->paper, "the paper's settings: Q = 0.3, r_i = 0.01");
    cmd->add_flag("--no-fault-detection", o->no_fault_detection, "fuse every finite reading");
    cmd->callback([o] { run_heading(*o); });
  }
  {
    auto o = std::make_shared<SimOptions>();
    std::string names;
    for (auto s : fusion::sim::heading_scenario_names())
      names += (names.empty() ? "" : ", ") + std::string(s);
    auto* cmd = app.add_subcommand("heading-sim", "Simulate N heading sensors: H.csv and truth");
    cmd->add_option("scenario", o->scenario, "scenario: " + names)->required();
    cmd->add_option("--seed", o->seed, "random seed")->capture_default_str();
    cmd->add_option("--out", o->out, "H.csv: t_s,h1_deg,...,hN_deg")->required();
    cmd->add_option("--truth", o->truth, "T.csv: t_s,heading_deg,rate_deg_s,fault1..faultN");
    cmd->callback([o] { run_heading_sim(*o); });
  }
  {
    auto o = std::make_shared<EvalOptions>();
    auto* cmd = app.add_subcommand(
        "heading-eval", "Table scenario x method: RMS, max error, NEES, isolation time (markdown)");
    cmd->add_option("--scenario", o->scenarios, "scenarios (default: all)")->delimiter(',');
    cmd->add_option("--method", o->methods, "methods (default: all)")->delimiter(',');
    cmd->add_option("--seeds", o->seeds, "seeds 1..N per scenario")->capture_default_str();
    cmd->callback([o] { run_heading_eval(*o); });
  }
}

}  // namespace telltale::cli
