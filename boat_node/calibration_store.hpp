#pragma once
/// \file
/// The boat node's sensor calibration across restarts: what the attitude filter had learnt of its
/// IMU (the gyro's bias, its common scale error, the accelerometer's skew and their covariance,
/// fusion::TelltaleCalibration), kept in a small JSON file. A node started again on the water
/// begins from it (TelltaleAttitudeFilter::warm_start) instead of the datasheet's spread: on the
/// BROAD recordings started in motion, 0.52 deg mean inclination error against 2.00 cold
/// (docs/attitude.md, "Started in motion").
///
/// The file says which sensor it describes (the IMU source, its axis remap and ranges, the
/// simulator's seed): a calibration is the sensor's, and another sensor's bias read as this one's
/// would be believed to 0.03 deg/s. It is written whole to a temporary file and renamed over the
/// old one, so a crash or a full disk mid-write leaves the previous calibration, never half of
/// one. Not synced to the medium: after a power cut the file may be the one before; it is only a
/// better start, and a file that does not parse is a cold start.

#include <optional>
#include <string>

#include "telltale/fusion/attitude_telltale.hpp"

namespace telltale::boat {

struct SavedCalibration {
  fusion::TelltaleCalibration calibration;
  std::string sensor;         ///< what it was learnt from (the node's sensor_identity)
  double saved_unix_s = 0.0;  ///< when (system clock)
};

/// The file at `path`: nullopt with `why` set when there is none or it is not a calibration
/// (unreadable, not JSON, a field missing or not finite, another format or version). Never
/// throws: a node must start whatever its state file holds.
[[nodiscard]] std::optional<SavedCalibration> load_calibration(const std::string& path,
                                                               std::string& why);

/// Writes `c` to `path` (via `path`.tmp and a rename). Throws std::runtime_error naming the file
/// and the reason when it cannot (a full disk, a read-only directory); the old file is then
/// left as it was.
void save_calibration(const std::string& path, const SavedCalibration& c);

/// Begins `filter` (before its first sample) from the calibration kept at `path` when it is
/// `sensor`'s, its age counted to `now_unix_s`; returns what it did, for the node to say: "PATH:
/// warm start, saved N s ago, gyro bias X Y Z deg/s", or why it is a cold start (nothing there,
/// unreadable, another sensor's, refused by the filter: a clock set back or values no filter
/// learns). Never a refusal to run.
[[nodiscard]] std::string restore_calibration(fusion::TelltaleAttitudeFilter& filter,
                                              const std::string& path, const std::string& sensor,
                                              double now_unix_s);

}  // namespace telltale::boat
