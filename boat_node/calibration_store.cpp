#include "calibration_store.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace telltale::boat {
namespace {

constexpr const char* kFormat = "telltale-imu-calibration";
constexpr int kVersion = 1;

/// A finite number from j[key], else throws with the key's name.
double number(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || !j.at(key).is_number()) throw std::invalid_argument(key);
  const double v = j.at(key).get<double>();
  if (!std::isfinite(v)) throw std::invalid_argument(key);
  return v;
}

}  // namespace

std::optional<SavedCalibration> load_calibration(const std::string& path, std::string& why) {
  std::ifstream in(path);
  if (!in) {
    why = "none yet";
    return std::nullopt;
  }
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    why = "not JSON";
    return std::nullopt;
  }
  // (Types checked first: json::value throws on a field of another type.)
  const auto format = j.find("format");
  const auto version = j.find("version");
  if (format == j.end() || !format->is_string() || format->get<std::string>() != kFormat ||
      version == j.end() || !version->is_number_integer() || version->get<int>() != kVersion) {
    why = std::string("not a ") + kFormat + " file of version " + std::to_string(kVersion);
    return std::nullopt;
  }
  try {
    SavedCalibration c;
    if (!j.contains("sensor") || !j.at("sensor").is_string()) throw std::invalid_argument("sensor");
    c.sensor = j.at("sensor").get<std::string>();
    c.saved_unix_s = number(j, "saved_unix_s");
    const auto& b = j.at("bias_rad_s");
    if (!b.is_array() || b.size() != 3) throw std::invalid_argument("bias_rad_s");
    for (int i = 0; i < 3; ++i) {
      if (!b[static_cast<std::size_t>(i)].is_number()) throw std::invalid_argument("bias_rad_s");
      c.calibration.bias_rad_s(i) = b[static_cast<std::size_t>(i)].get<double>();
    }
    c.calibration.gyro_scale = number(j, "gyro_scale");
    c.calibration.acc_skew_s = number(j, "acc_skew_s");
    const auto& p = j.at("covariance");
    if (!p.is_array() || p.size() != 5) throw std::invalid_argument("covariance");
    for (int r = 0; r < 5; ++r) {
      const auto& row = p[static_cast<std::size_t>(r)];
      if (!row.is_array() || row.size() != 5) throw std::invalid_argument("covariance");
      for (int k = 0; k < 5; ++k) {
        if (!row[static_cast<std::size_t>(k)].is_number())
          throw std::invalid_argument("covariance");
        c.calibration.cov(r, k) = row[static_cast<std::size_t>(k)].get<double>();
      }
    }
    if (!c.calibration.bias_rad_s.allFinite() || !c.calibration.cov.allFinite())
      throw std::invalid_argument("a value not finite");
    return c;
  } catch (const std::exception& e) {
    why = std::string("bad or missing field: ") + e.what();
    return std::nullopt;
  }
}

void save_calibration(const std::string& path, const SavedCalibration& c) {
  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["sensor"] = c.sensor;
  j["saved_unix_s"] = c.saved_unix_s;
  const auto& cal = c.calibration;
  j["bias_rad_s"] = {cal.bias_rad_s.x(), cal.bias_rad_s.y(), cal.bias_rad_s.z()};
  j["gyro_scale"] = cal.gyro_scale;
  j["acc_skew_s"] = cal.acc_skew_s;
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 5; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int k = 0; k < 5; ++k) row.push_back(cal.cov(r, k));
    rows.push_back(row);
  }
  j["covariance"] = rows;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp + ": " + std::strerror(errno));
    // (nlohmann writes the shortest text that reads back to the same double: bit for bit.)
    out << j.dump(1) << '\n';
    out.flush();
    if (!out) {
      const std::string reason = std::strerror(errno);
      std::remove(tmp.c_str());
      throw std::runtime_error("cannot write " + tmp + ": " + reason);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot replace " + path + ": " + reason);
  }
}

std::string restore_calibration(fusion::TelltaleAttitudeFilter& filter, const std::string& path,
                                const std::string& sensor, double now_unix_s) {
  std::string why;
  const auto saved = load_calibration(path, why);
  if (!saved) return path + ": " + why + "; cold start";
  if (saved->sensor != sensor)
    return path + " is of another sensor (" + saved->sensor + ", this one " + sensor +
           "); cold start";
  const double age_s = now_unix_s - saved->saved_unix_s;
  char text[160];
  if (!filter.warm_start(saved->calibration, age_s)) {
    std::snprintf(text, sizeof text,
                  ": refused (saved %.0f s ago: a clock set back, or values no filter learns); "
                  "cold start",
                  age_s);
    return path + text;
  }
  const Eigen::Vector3d b = saved->calibration.bias_rad_s * (180.0 / M_PI);
  std::snprintf(text, sizeof text, ": warm start, saved %.0f s ago, gyro bias %.3f %.3f %.3f deg/s",
                age_s, b.x(), b.y(), b.z());
  return path + text;
}

}  // namespace telltale::boat
