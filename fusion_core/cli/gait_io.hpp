#pragma once
/// \file
/// IMU CSV reading and gait-simulator CSV writing shared by the steps, pdr, gait-sim and
/// steps-eval subcommands (SPEC section 6 column names), and the one run of a phone walk that
/// `pdr` writes and `steps-eval` scores (run_handheld_walk).

#include <CLI/CLI.hpp>
#include <limits>
#include <string>
#include <vector>

#include "telltale/fusion/handheld_pdr.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"

namespace telltale::cli {

void register_pdr(CLI::App& app);  // registered by register_steps (cmd_pdr.cpp)

/// One row of an IMU CSV: gyro NaN when the file has no gyro columns, mag NaN without mag.
struct ImuRecord {
  fusion::ImuSample imu;
  Eigen::Vector3d mag_uT = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// Reads `t_s,ax_m_s2,ay_m_s2,az_m_s2` (required), `gx_rad_s,gy_rad_s,gz_rad_s` (required when
/// `require_gyro`), `mx_uT,my_uT,mz_uT` (optional). Throws io::CsvError on bad input.
///
/// Repeated time stamps (real phones write them: the OS stamps a batch of sensor events with
/// one delivery time) are accepted: the rows sharing a stamp are merged into one record, the
/// mean of their values (the file says they were measured at the same instant; inventing times
/// between them would be a guess, and averaging two readings of one instant only lowers their
/// noise -- steps are below 4 Hz, far under any rate that repeats stamps). `repeated_stamps`
/// receives how many rows were merged into the row before them. Time going backwards stays an
/// error naming the file, line and column.
[[nodiscard]] std::vector<ImuRecord> read_imu_csv(const std::string& path, bool require_gyro,
                                                  bool* has_gyro = nullptr, bool* has_mag = nullptr,
                                                  std::size_t* repeated_stamps = nullptr);

/// The recording as a sensor at `rate_hz` would have given it (fusion::resample_spans: averaged
/// over the interval before each sample below the recording's rate, interpolated above; the
/// field likewise, NaN staying NaN). Used by steps-eval's --rate-hz on the real recordings.
[[nodiscard]] std::vector<ImuRecord> resample_records(const std::vector<ImuRecord>& records,
                                                      double rate_hz);

/// A phone walk through HandheldPdr, as `fusion_cli pdr --mount phone` writes it and steps-eval
/// scores it: every step laid as walked, with the stands before it (`live`, the track
/// `wearable_node` publishes; fusion::TrackRelay), then the whole track re-laid with the gyro
/// bias the recording ended with (`steps`; fusion::relay_track). `ns_per_sample`: the updates' time
/// only.
struct HandheldWalk {
  std::vector<fusion::HandheldStep> steps;
  std::vector<fusion::HandheldStep> live;
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
  double ns_per_sample = 0.0;
};
[[nodiscard]] HandheldWalk run_handheld_walk(const std::vector<ImuRecord>& records,
                                             const fusion::HandheldPdrParams& params);

/// Writes the IMU CSV (t_s, gyro, acc, mag) and, if `truth_path` is not empty, the truth CSV:
/// t_s,x_m,y_m,heading_deg,distance_m,gait,pose,switching,steps,foot_steps,step_hz,step_length_m
/// (gait and pose as indexes: gait 0..4 = slow-walk..run, pose 0..3 = hand-held, call, pocket,
/// arm-swing).
void write_gait_run(const fusion::sim::GaitRun& run, const std::string& imu_path,
                    const std::string& truth_path);

}  // namespace telltale::cli
