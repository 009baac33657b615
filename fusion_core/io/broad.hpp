#pragma once
/// \file
/// Reads a BROAD trial in the CSV format of `data/broad/README.md` (TRIAL.imu.csv +
/// TRIAL.truth.csv) into a fusion::InclinationTrial. Rows are scored when movement = 1 and the
/// truth is not nan. Throws io::CsvError (file:line:column) on bad input.

#include <string>

#include "telltale/fusion/attitude_eval.hpp"

namespace telltale::io {

[[nodiscard]] fusion::InclinationTrial read_broad_trial(const std::string& imu_csv_path,
                                                        const std::string& truth_csv_path);

}  // namespace telltale::io
