// Accuracy of attitude filters against ground truth.
#include "telltale/fusion/attitude_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "telltale/fusion/attitude_speed.hpp"
#include "telltale/fusion/resample.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::fusion {
namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
Eigen::Vector3d up_of(double heel, double pitch) {
  return {std::sin(pitch), std::cos(pitch) * std::sin(heel), std::cos(pitch) * std::cos(heel)};
}
}  // namespace

void TiltErrorStats::merge(const TiltErrorStats& o) {
  const double n = static_cast<double>(samples + o.samples);
  if (n == 0.0) return;
  const auto rms = [&](double a, double b) {
    return std::sqrt(
        (a * a * static_cast<double>(samples) + b * b * static_cast<double>(o.samples)) / n);
  };
  heel_rms_deg = rms(heel_rms_deg, o.heel_rms_deg);
  pitch_rms_deg = rms(pitch_rms_deg, o.pitch_rms_deg);
  heel_max_deg = std::max(heel_max_deg, o.heel_max_deg);
  pitch_max_deg = std::max(pitch_max_deg, o.pitch_max_deg);
  samples += o.samples;
}

std::vector<TiltErrorStats> evaluate_on_scenario(const std::vector<std::string>& filter_names,
                                                 std::string_view scenario_name, std::uint64_t seed,
                                                 double rate_hz, double duration_s,
                                                 const sim::ImuErrorParams* errors) {
  const std::size_t n = filter_names.size();
  std::vector<TiltErrorStats> st(n);
  if (duration_s <= 0.0) duration_s = sim::scenario_default_duration_s(scenario_name);
  sim::ScenarioOptions options;
  if (errors != nullptr) options.errors = *errors;
  auto sc = sim::make_scenario(scenario_name, seed, rate_hz, duration_s, options);
  if (!sc) return st;
  // A boat's node is installed: configured with where its sensor sits from the boat's centre
  // (the point the GNSS fixes describe), as boat_node --sensor-offset does. The other scenarios
  // are no boat installation (a pendulum's bob, a desk, a turntable), and BROAD and the phones
  // have no centre to refer to: the filters there run as configured by default (no offset).
  const Eigen::Vector3d installed = sc->has_gnss() ? sc->lever_arm() : Eigen::Vector3d::Zero();
  std::vector<std::unique_ptr<AttitudeFilter>> filters;
  for (const auto& name : filter_names) filters.push_back(make_attitude_filter(name, installed));
  std::vector<double> se_h(n, 0.0);
  std::vector<double> se_p(n, 0.0);
  ImuSample imu;
  sim::AttitudeTruth truth;
  GroundSpeedHold speed;  // the boat node's way: the last GNSS speed, held with an age limit
  while (sc->next(imu, truth)) {
    const bool scored = truth.t_s >= sc->warmup_s();
    if (const auto& fix = sc->gnss_fix()) speed.on_fix(fix->t_s, fix->sog_m_s, fix->cog_deg);
    const double v = speed.speed_m_s(imu.t_s);
    const double dv = speed.rate_m_s2(imu.t_s);
    const double dcog = speed.cog_rate_rad_s(imu.t_s);
    for (std::size_t i = 0; i < n; ++i) {
      if (!filters[i]) continue;
      filters[i]->set_speed(v, dv, dcog);
      filters[i]->update(imu);
      if (!scored) continue;
      const AttitudeOutput o = filters[i]->output();
      const double eh =
          std::abs(std::remainder(o.heel_rad - truth.heel_rad, 2.0 * M_PI)) * kRadToDeg;
      const double ep = std::abs(o.pitch_rad - truth.pitch_rad) * kRadToDeg;
      se_h[i] += eh * eh;
      se_p[i] += ep * ep;
      st[i].heel_max_deg = std::max(st[i].heel_max_deg, eh);
      st[i].pitch_max_deg = std::max(st[i].pitch_max_deg, ep);
      ++st[i].samples;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (st[i].samples == 0) continue;
    st[i].heel_rms_deg = std::sqrt(se_h[i] / static_cast<double>(st[i].samples));
    st[i].pitch_rms_deg = std::sqrt(se_p[i] / static_cast<double>(st[i].samples));
  }
  return st;
}

double inclination_error_rad(double heel_a, double pitch_a, double heel_b, double pitch_b) {
  const Eigen::Vector3d a = up_of(heel_a, pitch_a);
  const Eigen::Vector3d b = up_of(heel_b, pitch_b);
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

InclinationTrial resample_trial(const InclinationTrial& trial, double rate_hz) {
  const auto& imu = trial.imu;
  if (imu.size() < 2 || !(rate_hz > 0.0)) return trial;
  // Only below the recording's rate: interpolated truth angles would cross their wrap.
  const double span = imu.back().t_s - imu.front().t_s;
  if (!(span / static_cast<double>(imu.size() - 1) < 1.0 / rate_hz)) return trial;
  std::vector<double> t;
  for (const auto& s : imu) t.push_back(s.t_s);
  InclinationTrial out;
  out.sensor = trial.sensor;
  for (const ResampleSpan& r : resample_spans(t, rate_hz)) {
    ImuSample s;
    s.t_s = r.t_s;
    s.gyro_body_rad_s = resampled(r, [&](std::size_t i) { return imu[i].gyro_body_rad_s; });
    s.acc_body_m_s2 = resampled(r, [&](std::size_t i) { return imu[i].acc_body_m_s2; });
    out.imu.push_back(s);
    out.heel_true_rad.push_back(trial.heel_true_rad[r.last]);
    out.pitch_true_rad.push_back(trial.pitch_true_rad[r.last]);
    out.scored.push_back(trial.scored[r.last]);
  }
  return out;
}

std::size_t first_scored(const InclinationTrial& trial) {
  const auto it = std::find(trial.scored.begin(), trial.scored.end(), 1);
  return static_cast<std::size_t>(it - trial.scored.begin());
}

InclinationTrial trial_from(const InclinationTrial& trial, std::size_t from) {
  const auto cut = [from](const auto& v) {
    using V = std::decay_t<decltype(v)>;
    return from >= v.size() ? V{} : V(v.begin() + static_cast<std::ptrdiff_t>(from), v.end());
  };
  return {cut(trial.imu), cut(trial.heel_true_rad), cut(trial.pitch_true_rad), cut(trial.scored),
          trial.sensor};
}

double inclination_rmse_deg(AttitudeFilter& filter, const InclinationTrial& trial) {
  double se = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < trial.imu.size(); ++i) {
    filter.update(trial.imu[i]);
    if (!trial.scored[i]) continue;
    const AttitudeOutput o = filter.output();
    const double e = inclination_error_rad(o.heel_rad, o.pitch_rad, trial.heel_true_rad[i],
                                           trial.pitch_true_rad[i]);
    se += e * e;
    ++n;
  }
  return n == 0 ? 0.0 : std::sqrt(se / static_cast<double>(n)) * kRadToDeg;
}

}  // namespace telltale::fusion
