#pragma once
/// \file
/// The one clock a node stamps every record of a run with: the wall clock read once when the
/// run starts, then advanced by the monotonic clock.
///
/// Why not the wall clock at each record: a boat computer's wall clock steps. A board without a
/// battery-backed clock boots at its last saved time and is stepped by NTP or by chrony from
/// the GNSS minutes later; an operator sets the date by hand. A step back would give records
/// of one run the same or earlier times than records already sent, and the shore keeps one
/// record per (boat, time): the later fix would be lost as a duplicate and the track would fold
/// back on itself. Attitude samples have always been stamped this way (the run's start plus the
/// sample clock); fixes, wind readings and the status now share the base, so every record of a
/// run is on one time line. How far that line is from true UTC is what the GNSS time measures
/// (the gate's clock offset), reported beside the shore's own estimate.

#include <chrono>
#include <cstdint>

#include "shutdown.hpp"

namespace telltale::boat {

class RunClock {
 public:
  using Steady = std::chrono::steady_clock;

  /// Starts now: the wall clock read once.
  RunClock() : RunClock(Steady::now(), utc_now_ns()) {}
  RunClock(Steady::time_point start, std::uint64_t start_utc_ns)
      : start_(start), start_utc_ns_(start_utc_ns) {}

  /// The run's time at monotonic instant `t`, ns since 1970 (never before the run's start).
  [[nodiscard]] std::uint64_t at(Steady::time_point t) const {
    if (t <= start_) return start_utc_ns_;
    return start_utc_ns_ +
           static_cast<std::uint64_t>(
               std::chrono::duration_cast<std::chrono::nanoseconds>(t - start_).count());
  }
  [[nodiscard]] std::uint64_t now_ns() const { return at(Steady::now()); }

 private:
  Steady::time_point start_;
  std::uint64_t start_utc_ns_;
};

}  // namespace telltale::boat
