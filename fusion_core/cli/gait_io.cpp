#include "gait_io.hpp"

#include <chrono>

#include "csv.hpp"
#include "telltale/fusion/resample.hpp"

namespace telltale::cli {

std::vector<ImuRecord> read_imu_csv(const std::string& path, bool require_gyro, bool* has_gyro,
                                    bool* has_mag, std::size_t* repeated_stamps) {
  io::CsvReader reader(path,
                       {{"t_s"},
                        {"ax_m_s2"},
                        {"ay_m_s2"},
                        {"az_m_s2"},
                        {"gx_rad_s", require_gyro},
                        {"gy_rad_s", require_gyro},
                        {"gz_rad_s", require_gyro},
                        {"mx_uT", false, true},
                        {"my_uT", false, true},
                        {"mz_uT", false, true}},
                       "t_s", io::TimeOrder::kNonDecreasing);
  const bool gyro = reader.has_column("gx_rad_s") && reader.has_column("gy_rad_s") &&
                    reader.has_column("gz_rad_s");
  const bool mag =
      reader.has_column("mx_uT") && reader.has_column("my_uT") && reader.has_column("mz_uT");
  if (has_gyro) *has_gyro = gyro;
  if (has_mag) *has_mag = mag;
  std::vector<ImuRecord> out;
  std::vector<double> row;
  std::size_t merged = 1;  // rows averaged into out.back()
  while (reader.next(row)) {
    ImuRecord r;
    r.imu.t_s = row[0];
    r.imu.acc_body_m_s2 = {row[1], row[2], row[3]};
    r.imu.gyro_body_rad_s =
        gyro ? Eigen::Vector3d(row[4], row[5], row[6]) : Eigen::Vector3d::Constant(std::nan(""));
    if (mag) r.mag_uT = {row[7], row[8], row[9]};
    if (!out.empty() && r.imu.t_s == out.back().imu.t_s) {
      // A repeated stamp: running mean of the rows that share it (NaN stays NaN: missing).
      ++merged;
      const double k = 1.0 / static_cast<double>(merged);
      auto& m = out.back();
      m.imu.acc_body_m_s2 += k * (r.imu.acc_body_m_s2 - m.imu.acc_body_m_s2);
      m.imu.gyro_body_rad_s += k * (r.imu.gyro_body_rad_s - m.imu.gyro_body_rad_s);
      m.mag_uT += k * (r.mag_uT - m.mag_uT);
      continue;
    }
    merged = 1;
    out.push_back(r);
  }
  if (repeated_stamps) *repeated_stamps = reader.repeated_times();
  if (out.empty()) throw io::CsvError(path + ":2:0: no data rows");
  return out;
}

void write_gait_run(const fusion::sim::GaitRun& run, const std::string& imu_path,
                    const std::string& truth_path) {
  io::CsvWriter imu(imu_path, {"t_s", "gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2",
                               "az_m_s2", "mx_uT", "my_uT", "mz_uT"});
  for (const auto& s : run.samples) {
    const auto& g = s.imu.gyro_body_rad_s;
    const auto& a = s.imu.acc_body_m_s2;
    imu.row({s.imu.t_s, g.x(), g.y(), g.z(), a.x(), a.y(), a.z(), s.mag_uT.x(), s.mag_uT.y(),
             s.mag_uT.z()});
  }
  imu.close();
  if (truth_path.empty()) return;
  io::CsvWriter truth(truth_path, {"t_s", "x_m", "y_m", "heading_deg", "distance_m", "gait", "pose",
                                   "switching", "steps", "foot_steps", "step_hz", "step_length_m"});
  for (const auto& s : run.samples)
    truth.row({s.imu.t_s, s.x_m, s.y_m, s.heading_deg, s.distance_m, static_cast<double>(s.gait),
               static_cast<double>(s.pose), s.switching ? 1.0 : 0.0, static_cast<double>(s.steps),
               static_cast<double>(s.foot_steps), s.step_hz, s.step_length_m});
  truth.close();
}

HandheldWalk run_handheld_walk(const std::vector<ImuRecord>& records,
                               const fusion::HandheldPdrParams& params) {
  HandheldWalk walk;
  fusion::HandheldPdr pdr(params);
  std::chrono::nanoseconds spent{0};
  for (const auto& r : records) {
    const auto t0 = std::chrono::steady_clock::now();
    const int n = pdr.update(r.imu, r.mag_uT);
    spent += std::chrono::steady_clock::now() - t0;
    for (int k = 0; k < n; ++k) walk.steps.push_back(pdr.steps()[static_cast<std::size_t>(k)]);
  }
  walk.gyro_bias_rad_s = pdr.gyro_bias_rad_s();
  walk.live = walk.steps;
  fusion::relay_track(walk.steps, walk.gyro_bias_rad_s);
  if (!records.empty())
    walk.ns_per_sample = static_cast<double>(spent.count()) / static_cast<double>(records.size());
  return walk;
}

std::vector<ImuRecord> resample_records(const std::vector<ImuRecord>& records, double rate_hz) {
  std::vector<double> t;
  for (const auto& r : records) t.push_back(r.imu.t_s);
  std::vector<ImuRecord> out;
  for (const fusion::ResampleSpan& span : fusion::resample_spans(t, rate_hz)) {
    ImuRecord r;
    r.imu.t_s = span.t_s;
    r.imu.gyro_body_rad_s =
        fusion::resampled(span, [&](std::size_t i) { return records[i].imu.gyro_body_rad_s; });
    r.imu.acc_body_m_s2 =
        fusion::resampled(span, [&](std::size_t i) { return records[i].imu.acc_body_m_s2; });
    r.mag_uT = fusion::resampled(span, [&](std::size_t i) { return records[i].mag_uT; });
    out.push_back(r);
  }
  return out;
}

}  // namespace telltale::cli
