// Scoring of heading fusion runs against simulator truth (see heading_eval.hpp).
#include "telltale/fusion/sim/heading_eval.hpp"

#include <array>
#include <cmath>
#include <limits>

namespace telltale::fusion::sim {
namespace {

bool fused_now(HeadingSensorStatus s) {
  return s == HeadingSensorStatus::kInUse || s == HeadingSensorStatus::kNoReading;
}

}  // namespace

HeadingRunResult run_heading(const HeadingScenario& scenario,
                             const std::vector<HeadingSimSample>& samples,
                             HeadingFusionParams params) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const int n = static_cast<int>(scenario.sensors.size());
  params.sensor_count = n;
  HeadingFusion fusion(params);
  HeadingRunResult res;
  const std::size_t m = samples.size();
  res.fused_deg.resize(m);
  res.error_deg.resize(m);
  res.nees.assign(m, kNaN);
  res.in_use.resize(m);
  std::vector<std::array<HeadingSensorStatus, kMaxHeadingSensors>> status(m);
  std::array<double, kMaxHeadingSensors> y{};
  double sq = 0.0;
  double nees_sum = 0.0;
  std::size_t scored = 0;
  std::size_t nees_count = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const HeadingSimSample& s = samples[k];
    for (int i = 0; i < n; ++i)
      y[static_cast<std::size_t>(i)] = s.reading_deg[static_cast<std::size_t>(i)];
    fusion.update(s.t_s, y.data());
    res.fused_deg[k] = fusion.heading_deg();
    res.error_deg[k] = wrap_180_deg(fusion.heading_deg() - s.truth_heading_deg);
    res.in_use[k] = fusion.diagnostics().sensors_in_use;
    status[k] = fusion.diagnostics().status;
    if (params.method != HeadingMethod::kAverage && fusion.initialised()) {
      const HeadingFusion::Vec2 e(res.error_deg[k], fusion.rate_deg_s() - s.truth_rate_deg_s);
      const HeadingFusion::Mat2& p = fusion.state().p;
      if (p.determinant() > 0.0) res.nees[k] = e.dot(p.inverse() * e);
    }
    if (s.t_s < kHeadingSettleS) continue;
    ++scored;
    sq += res.error_deg[k] * res.error_deg[k];
    res.max_err_deg = std::max(res.max_err_deg, std::abs(res.error_deg[k]));
    if (std::isfinite(res.nees[k])) {
      nees_sum += res.nees[k];
      ++nees_count;
    }
  }
  res.rms_deg = scored > 0 ? std::sqrt(sq / static_cast<double>(scored)) : kNaN;
  res.mean_nees = nees_count > 0 ? nees_sum / static_cast<double>(nees_count) : kNaN;
  res.model_mismatches = fusion.diagnostics().model_mismatches;
  res.exclusions = fusion.diagnostics().exclusions;

  for (const HeadingFault& f : scenario.faults) {
    HeadingFaultOutcome o;
    o.sensor = f.sensor;
    o.harm_t_s = kNaN;
    const auto ui = static_cast<std::size_t>(f.sensor);
    std::size_t harm_k = m;
    for (std::size_t k = 0; k < m; ++k) {
      const HeadingSimSample& s = samples[k];
      if (s.t_s < f.t_start_s || s.t_s >= f.t_end_s) continue;
      const double r = s.reading_deg[ui];
      // The sensor's own error: against the truth of latency_s ago (first order in the rate).
      const double seen = s.truth_heading_deg - s.truth_rate_deg_s * scenario.sensors[ui].latency_s;
      const bool harmful = f.kind == HeadingFaultKind::kSilent
                               ? true
                               : std::isfinite(r) && std::abs(wrap_180_deg(r - seen)) > 1.0;
      if (harmful) {
        harm_k = k;
        o.harm_t_s = s.t_s;
        break;
      }
    }
    for (std::size_t k = harm_k; k < m; ++k) {
      if (!fused_now(status[k][ui]) ||
          (f.kind == HeadingFaultKind::kSilent && status[k][ui] == HeadingSensorStatus::kSilent)) {
        o.isolation_s = samples[k].t_s - o.harm_t_s;
        break;
      }
      if (samples[k].t_s >= f.t_end_s) break;
    }
    for (std::size_t k = 1; k < m; ++k) {
      if (samples[k].t_s < f.t_end_s) continue;
      if ((static_cast<unsigned>(res.in_use[k]) >> f.sensor) & 1u) {
        o.readmit_s = samples[k].t_s - f.t_end_s;
        o.readmit_jump_deg = std::abs(res.error_deg[k] - res.error_deg[k - 1]);
        break;
      }
    }
    res.faults.push_back(o);
  }
  return res;
}

}  // namespace telltale::fusion::sim
