#pragma once
// The Oxford step counter traces copied into tests/data/oxford_steps (CC BY 4.0, see its
// README): 24 traces, 7 carrying positions, 3 phones, accelerometer only, 50 Hz. One reader for
// the tests that use them.
#include <cstddef>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "csv.hpp"
#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

struct OxfordTrace {
  std::string name;
  std::size_t steps = 0;           ///< the trace's counted steps (counts.csv)
  std::vector<ImuSample> samples;  ///< the gyro NaN: not recorded
};

/// Every trace of counts.csv; empty if the folder is missing.
inline std::vector<OxfordTrace> read_oxford_traces() {
  const std::string dir = std::string(TELLTALE_TEST_DATA_DIR) + "/oxford_steps";
  std::vector<OxfordTrace> traces;
  std::ifstream counts(dir + "/counts.csv");
  std::string line;
  std::getline(counts, line);  // header
  const double nan = std::numeric_limits<double>::quiet_NaN();
  while (std::getline(counts, line)) {
    OxfordTrace tr;
    tr.name = line.substr(0, line.find(','));
    tr.steps = static_cast<std::size_t>(std::stoi(line.substr(line.rfind(',') + 1)));
    const auto table = io::read_csv(dir + "/" + tr.name + ".imu.csv",
                                    {{"t_s"}, {"ax_m_s2"}, {"ay_m_s2"}, {"az_m_s2"}}, "t_s");
    for (std::size_t i = 0; i < table.rows(); ++i)
      tr.samples.push_back({table.columns[0][i],
                            {nan, nan, nan},
                            {table.columns[1][i], table.columns[2][i], table.columns[3][i]}});
    traces.push_back(std::move(tr));
  }
  return traces;
}

}  // namespace telltale::fusion
