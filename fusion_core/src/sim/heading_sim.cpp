// Heading sensor simulator: profiles, sensors, faults (see heading_sim.hpp).
#include "telltale/fusion/sim/heading_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace telltale::fusion::sim {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

/// A smooth turn of delta_deg starting at t0_s and lasting dur_s (raised cosine in heading).
double turn(double t_s, double t0_s, double dur_s, double delta_deg) {
  if (t_s <= t0_s) return 0.0;
  if (t_s >= t0_s + dur_s) return delta_deg;
  return delta_deg * 0.5 * (1.0 - std::cos(M_PI * (t_s - t0_s) / dur_s));
}

/// Unwrapped heading of the analytic profiles, deg.
double analytic_heading_deg(HeadingProfile p, double t_s) {
  switch (p) {
    case HeadingProfile::kSmallChange:
      return 45.0 + 1.5 * std::sin(kTwoPi * t_s / 40.0) + 0.6 * std::sin(kTwoPi * t_s / 11.0 + 1.0);
    case HeadingProfile::kLargeChange:
      // 30 -> 120 -> 350 (through north) -> 140 -> 80, each turn at 2 deg/s mean, 3.1 peak.
      return 30.0 + turn(t_s, 20.0, 45.0, 90.0) + turn(t_s, 75.0, 65.0, -130.0) +
             turn(t_s, 150.0, 75.0, 150.0) + turn(t_s, 235.0, 30.0, -60.0);
    case HeadingProfile::kDinghy: {
      // Beating to windward, wind from 000: 45 and 315 deg, tacks (90 deg in 4 s) through north.
      static constexpr double kTacks[] = {15.0,  40.0,  62.0,  90.0, 115.0,
                                          140.0, 165.0, 190.0, 215.0};
      double h = 45.0;
      double sign = -1.0;
      for (double t0 : kTacks) {
        h += turn(t_s, t0, 4.0, sign * 90.0);
        sign = -sign;
      }
      return h + 2.0 * std::sin(kTwoPi * t_s / 3.5) + 1.0 * std::sin(kTwoPi * t_s / 7.3 + 0.5) +
             3.0 * std::sin(kTwoPi * t_s / 90.0);
    }
    case HeadingProfile::kModel:
      break;
  }
  return 0.0;
}

struct Truth {
  std::vector<double> heading_deg;  // unwrapped, per tick
  std::vector<double> rate_deg_s;
};

Truth make_truth(const HeadingScenario& sc, std::mt19937_64& rng, std::size_t ticks) {
  Truth tr;
  tr.heading_deg.resize(ticks);
  tr.rate_deg_s.resize(ticks);
  if (sc.profile == HeadingProfile::kModel) {
    // x(k+1) = F x(k) + G w(k), w ~ N(0, Q): exactly the model the filters assume.
    std::normal_distribution<double> w(0.0, std::sqrt(sc.fusion.accel_var_deg2_s4));
    double h = 100.0;
    double r = 0.0;
    for (std::size_t k = 0; k < ticks; ++k) {
      tr.heading_deg[k] = h;
      tr.rate_deg_s[k] = r;
      h += sc.dt_s * r;
      r += sc.dt_s * w(rng);
    }
    return tr;
  }
  for (std::size_t k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * sc.dt_s;
    constexpr double kEps = 1e-4;
    tr.heading_deg[k] = analytic_heading_deg(sc.profile, t);
    tr.rate_deg_s[k] =
        (analytic_heading_deg(sc.profile, t + kEps) - analytic_heading_deg(sc.profile, t - kEps)) /
        (2.0 * kEps);
  }
  return tr;
}

/// Unwrapped truth at time t_s (linear between ticks; before the start: the first value).
double truth_at(const HeadingScenario& sc, const Truth& tr, double t_s) {
  if (sc.profile != HeadingProfile::kModel) return analytic_heading_deg(sc.profile, t_s);
  const double u = std::max(t_s, 0.0) / sc.dt_s;
  const auto k = static_cast<std::size_t>(std::floor(u));
  if (k + 1 >= tr.heading_deg.size()) return tr.heading_deg.back();
  const double f = u - static_cast<double>(k);
  return (1.0 - f) * tr.heading_deg[k] + f * tr.heading_deg[k + 1];
}

HeadingScenario paper(std::string name, HeadingProfile profile, double duration_s) {
  HeadingScenario sc;
  sc.name = std::move(name);
  sc.profile = profile;
  sc.duration_s = duration_s;
  sc.dt_s = 0.1;
  sc.sensors.assign(3, HeadingSensorModel{});  // r_i = 0.01 deg^2, 10 Hz, no latency
  sc.fusion = HeadingFusionParams::paper();
  return sc;
}

HeadingScenario dinghy(std::string name) {
  HeadingScenario sc;
  sc.name = std::move(name);
  sc.profile = HeadingProfile::kDinghy;
  sc.duration_s = 240.0;
  sc.dt_s = 0.1;
  // A fluxgate at 10 Hz, a MEMS AHRS at 10 Hz with 50 ms of filtering delay, a dual-antenna GNSS
  // compass at 5 Hz arriving 100 ms late. Each sigma 0.1 deg.
  sc.sensors = {HeadingSensorModel{0.1, 0.0, 0.0, 1, 0, 0.0},
                HeadingSensorModel{0.1, 0.0, 0.05, 1, 0, 0.0},
                HeadingSensorModel{0.1, 0.0, 0.10, 2, 1, 0.0}};
  sc.fusion = HeadingFusionParams{};
  sc.fusion.sensor_count = 3;
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    sc.fusion.noise_deg[i] = sc.sensors[i].noise_deg;
    sc.fusion.latency_s[i] = sc.sensors[i].latency_s;
  }
  return sc;
}

}  // namespace

std::vector<std::string_view> heading_scenario_names() {
  return {"paper-small",  "paper-large",   "paper-model",   "dinghy",      "dinghy-frozen",
          "dinghy-drift", "dinghy-spikes", "dinghy-silent", "dinghy-bias", "dinghy-two-fail"};
}

std::optional<HeadingScenario> heading_scenario(std::string_view name) {
  if (name == "paper-small") return paper("paper-small", HeadingProfile::kSmallChange, 120.0);
  if (name == "paper-large") return paper("paper-large", HeadingProfile::kLargeChange, 280.0);
  if (name == "paper-model") return paper("paper-model", HeadingProfile::kModel, 120.0);
  if (name == "dinghy") return dinghy("dinghy");
  // The faulty sensor is the second one; faults start at 60 s and end at 180 s.
  HeadingFault f{1, HeadingFaultKind::kFrozen, 60.0, 180.0, 0.0, 0.0};
  if (name == "dinghy-frozen") {
  } else if (name == "dinghy-drift") {
    f.kind = HeadingFaultKind::kDrift;
    f.magnitude = 2.5;  // deg/min
  } else if (name == "dinghy-spikes") {
    f.kind = HeadingFaultKind::kSpikes;
    f.magnitude = 25.0;
    f.probability = 0.05;
  } else if (name == "dinghy-silent") {
    f.kind = HeadingFaultKind::kSilent;
    f.t_end_s = 120.0;  // one minute
  } else if (name == "dinghy-bias") {
    f.kind = HeadingFaultKind::kBiasStep;
    f.magnitude = 4.0;
  } else if (name == "dinghy-two-fail") {
    HeadingScenario sc = dinghy(std::string(name));
    sc.faults.push_back({0, HeadingFaultKind::kSilent, 50.0, 1e9, 0.0, 0.0});
    sc.faults.push_back({1, HeadingFaultKind::kBiasStep, 80.0, 180.0, 4.0, 0.0});
    return sc;
  } else {
    return std::nullopt;
  }
  HeadingScenario sc = dinghy(std::string(name));
  sc.faults.push_back(f);
  return sc;
}

bool heading_fault_active(const HeadingScenario& scenario, int sensor, double t_s) {
  return std::any_of(scenario.faults.begin(), scenario.faults.end(), [&](const HeadingFault& f) {
    return f.sensor == sensor && t_s >= f.t_start_s && t_s < f.t_end_s;
  });
}

std::vector<HeadingSimSample> simulate_heading(const HeadingScenario& sc, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const auto ticks = static_cast<std::size_t>(std::floor(sc.duration_s / sc.dt_s + 0.5)) + 1;
  const Truth tr = make_truth(sc, rng, ticks);
  const std::size_t n = sc.sensors.size();
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<double> held(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<HeadingSimSample> out(ticks);
  for (std::size_t k = 0; k < ticks; ++k) {
    HeadingSimSample& s = out[k];
    s.t_s = static_cast<double>(k) * sc.dt_s;
    s.truth_heading_deg = wrap_360_deg(tr.heading_deg[k]);
    s.truth_rate_deg_s = tr.rate_deg_s[k];
    s.reading_deg.assign(n, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < n; ++i) {
      const HeadingSensorModel& m = sc.sensors[i];
      const int period = std::max(m.period_ticks, 1);
      // Noise is drawn every tick for every sensor so that one sensor's rate or fault does not
      // change the noise sequence of the others (paired comparisons across scenarios).
      const double noise = m.noise_deg * unit(rng);
      const double u_spike = uni(rng);
      const double u_sign = uni(rng);
      if (static_cast<int>(k % static_cast<std::size_t>(period)) != m.offset_ticks % period)
        continue;
      double y = truth_at(sc, tr, s.t_s - m.latency_s) + m.bias_deg + noise;
      if (m.resolution_deg > 0.0) y = std::round(y / m.resolution_deg) * m.resolution_deg;
      bool silent = false;
      bool frozen = false;
      for (const HeadingFault& f : sc.faults) {
        if (f.sensor != static_cast<int>(i) || s.t_s < f.t_start_s || s.t_s >= f.t_end_s) continue;
        switch (f.kind) {
          case HeadingFaultKind::kFrozen:
            frozen = true;
            break;
          case HeadingFaultKind::kDrift:
            y += f.magnitude / 60.0 * (s.t_s - f.t_start_s);
            break;
          case HeadingFaultKind::kSpikes:
            if (u_spike < f.probability) y += (u_sign < 0.5 ? -1.0 : 1.0) * f.magnitude;
            break;
          case HeadingFaultKind::kSilent:
            silent = true;
            break;
          case HeadingFaultKind::kBiasStep:
            y += f.magnitude;
            break;
        }
      }
      if (silent) continue;
      if (frozen && std::isfinite(held[i])) {
        y = held[i];
      } else {
        y = wrap_360_deg(y);
        held[i] = y;
      }
      s.reading_deg[i] = y;
    }
  }
  return out;
}

}  // namespace telltale::fusion::sim
