#include "telltale/fusion/pdr/sensor_prep.hpp"

namespace telltale::fusion {

bool SensorPrep::prepare(const ImuSample& raw, const Eigen::Vector3d& mag_uT, ImuGateCounts& counts,
                         ImuSample& s, Eigen::Vector3d& mag) {
  static constexpr ImuGateParams kGate{.gyro_required = false};
  ImuSample local = raw;
  local.t_s = clock_.to_local(raw.t_s);
  if (gate_imu_sample(local, kGate, have_t_, last_t_s_, counts).verdict == ImuVerdict::kReject)
    return false;
  s = local;
  if (s.gyro_body_rad_s.allFinite()) {
    gyro_bias_.add(s);
    s.gyro_body_rad_s -= gyro_bias_.bias_rad_s();
  }
  mag = mag_uT;
  if (calibrate_mag_ && mag.allFinite()) {
    mag_cal_.update(s.t_s, s.gyro_body_rad_s, mag);
    mag = mag_cal_.corrected(mag);
  }
  return true;
}

bool SensorPrep::arrive(const ImuSample& raw, const Eigen::Vector3d& mag_uT, PrepCounts& counts,
                        PdrOutput& out, ImuSample& s, Eigen::Vector3d& mag) {
  out.step = false;
  if (!prepare(raw, mag_uT, counts, s, mag)) return false;
  counts.still_windows = still_windows();
  out.t_s = raw.t_s;
  return true;
}

}  // namespace telltale::fusion
