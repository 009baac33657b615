#pragma once
/// \file
/// Where the boat node's IMU samples come from. A source hands out samples in time order; the
/// node paces itself on `t_s` when the source is real time.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/sim/race.hpp"

namespace telltale::boat {

class ImuSource {
 public:
  virtual ~ImuSource() = default;
  /// The next sample, or nothing at the end (a replay without loop). May throw
  /// io::CsvError for a bad replay file (the node reports it and stops).
  virtual std::optional<fusion::ImuSample> next() = 0;
  /// True when samples must be consumed at the pace of t_s (sim, real-time replay).
  [[nodiscard]] virtual bool real_time() const = 0;
  [[nodiscard]] virtual std::string describe() const = 0;
};

struct ReplayOptions {
  bool fast = false;  ///< as fast as possible instead of real time
  bool loop = false;  ///< start again at the end (time keeps increasing)
};

/// "sim" (the race scenario), "sim:SCENARIO", "replay:FILE.csv" or "witmotion:DEVICE[@BAUD]".
/// Throws std::invalid_argument for an unknown source, io::CsvError for an unreadable replay
/// file, std::system_error for a device. `stop` ends a wait for a device. `race`: the course the
/// race scenario ("sim", "sim:race") sails, shared with the node's simulated receiver so both
/// are one boat (CourseSim); null: a course of its own from `seed`.
std::unique_ptr<ImuSource> make_imu_source(const std::string& spec, std::uint64_t seed,
                                           double sim_rate_hz, const ReplayOptions& replay,
                                           const std::function<bool()>& stop,
                                           std::shared_ptr<fusion::sim::RaceCourse> race = nullptr);

/// True for the sources that run the race scenario ("sim", "sim:race").
[[nodiscard]] bool is_race_source(const std::string& spec);

}  // namespace telltale::boat
