// BROAD trial reader (the metric lives in fusion_core's attitude_eval).
#include "broad.hpp"

#include <cmath>

#include "csv.hpp"

namespace telltale::io {

fusion::InclinationTrial read_broad_trial(const std::string& imu_path,
                                          const std::string& truth_path) {
  constexpr double kDeg = M_PI / 180.0;
  const CsvTable imu = read_csv(
      imu_path,
      {{"t_s"}, {"gx_rad_s"}, {"gy_rad_s"}, {"gz_rad_s"}, {"ax_m_s2"}, {"ay_m_s2"}, {"az_m_s2"}},
      "t_s");
  const CsvTable truth =
      read_csv(truth_path,
               {{"t_s"}, {"heel_deg", true, true}, {"pitch_deg", true, true}, {"movement"}}, "t_s");
  if (truth.rows() != imu.rows()) {
    throw CsvError(truth_path + ":1:1: " + std::to_string(truth.rows()) +
                   " rows, but the IMU file has " + std::to_string(imu.rows()));
  }
  fusion::InclinationTrial tr;
  // The dataset's IMU (myon aktos-t): +-2000 deg/s and +-16 g. The recordings reach 1352 deg/s
  // (trial 08) and 9.6 g (16), unclipped; read with the boat instrument's 250 deg/s and 2 g, a
  // third of 08's and 29's samples would be taken for clipped ones.
  tr.sensor.gyro_rad_s = 2000.0 * kDeg;
  tr.sensor.acc_m_s2 = 16.0 * fusion::kStandardGravity_m_s2;
  const std::size_t n = imu.rows();
  tr.imu.resize(n);
  tr.heel_true_rad.resize(n);
  tr.pitch_true_rad.resize(n);
  tr.scored.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    tr.imu[i].t_s = imu.columns[0][i];
    tr.imu[i].gyro_body_rad_s = {imu.columns[1][i], imu.columns[2][i], imu.columns[3][i]};
    tr.imu[i].acc_body_m_s2 = {imu.columns[4][i], imu.columns[5][i], imu.columns[6][i]};
    tr.heel_true_rad[i] = truth.columns[1][i] * kDeg;
    tr.pitch_true_rad[i] = truth.columns[2][i] * kDeg;
    tr.scored[i] = truth.columns[3][i] == 1.0 && std::isfinite(tr.heel_true_rad[i]) &&
                   std::isfinite(tr.pitch_true_rad[i]);
  }
  return tr;
}

}  // namespace telltale::io
