#pragma once
/// \file
/// Each live boat's manoeuvres found once, as its samples arrive, and pushed to the dashboards:
/// the fleet cards no longer ask the store for them (a poll per dashboard and boat re-read the
/// last minute of every boat from SQLite every 5 s).
///
/// ManoeuvreTracker keeps, per boat, the last `window_s` (90 s) of fixes (COG, SOG) and attitude
/// (heel, pitch) and runs the session review's own detector (telltale/fusion/manoeuvres.hpp,
/// analyse_manoeuvres, every definition there) on that window each time `run_every_s` (2 s) of
/// fixes has come in. 90 s holds a manoeuvre's every window (20 s before t0 to 25 s after, and
/// the 10 s of course before its turn's start) from the moment it is found (~10-15 s after t0)
/// until it is final, with room before for the turn it may be merged with.
///
/// A manoeuvre is reported twice: when first found (metrics still measuring) and when final:
///  - the data reaches the end of its windows: t0 + `final_after_s` (25 s: exit SOG, exit heel),
///    for a turn longer than ~14 s (a 720) 16 s after its end (the course after it); and
///  - the boat has sailed a steady course (COG within kQuietDeg of its mean) for the last
///    kQuietS seconds. A turn begun since would still change the manoeuvre in the detector once
///    found (10 s after its middle): merged with it within the 20 s debounce, as the halves of
///    a 720 are, or cutting short its course after, as the rounding after a layline tack does.
///    A boat that never steadies gets its final report at t0 + kFinalByS.
/// In the simulated races 3 in 4 are final 25-27 s after t0, the others (a layline tack and the
/// rounding after it) 34-45 s. Two runs' manoeuvres are one when their t0s are within
/// kSameManoeuvreS (t0 settles as the course after the turn comes in).
///
/// The kind (and vmg_lost_m) depends on the wind, which one or two turns in 90 s do not tell: a
/// boat's runs are given the wind estimated (fusion::estimate_wind, the detector's own estimate)
/// from its final manoeuvres of the session so far (the last kMaxHistory; a gap of
/// `session_gap_s` in its fixes starts a new session, as in the store). The review estimates it
/// from the whole session; before the first final tack or gybe, from the window alone.
///
/// Where the live report can differ from the review of the whole session:
///  - the wind: the session so far, not all of it (a kind changes only where the wind is
///    ambiguous: near the 50-140 deg bounds, or before the session's first tack or gybe);
///  - recovery_s is null when the boat had not recovered by the final report (the review looks
///    up to 60 s on);
///  - a turn of a boat that never steadies, final at t0 + kFinalByS, may still change.
///
/// Cost per sample O(1) amortised (a deque push and trim); the detector, O(window), runs per boat
/// every 2 s of data: measured 62 us of CPU per boat and second of data, 6 % of one core for
/// 1000 boats (bench/manoeuvre_live_bench.cpp). Memory per boat is bounded by the window and by
/// a cap on samples (a boat publishing faster than 20 fixes / 50 attitude samples a second keeps
/// less than 90 s).
/// Single-threaded: every call from one thread (the shore's live worker).

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "fleet.hpp"
#include "telltale/fusion/manoeuvres.hpp"

namespace telltale::shore {

class LiveHub;

/// One report of a manoeuvre: when first found (final false) and when its metrics are final.
struct LiveManoeuvre {
  std::string boat_id;
  fusion::Manoeuvre manoeuvre;  ///< times in seconds from the boat's time base
  std::uint64_t t0_utc_ns = 0;  ///< t0 on the boat's clock, ns since 1970
  bool final = false;
};

/// Two runs' manoeuvres whose t0s are this close are one manoeuvre.
/// (A candidate merged into a larger turn within the detector's 20 s debounce moves t0 by up to
/// ~9 s: the layline tack that the mark rounding right after it takes in.)
inline constexpr double kSameManoeuvreS = 12.0;
/// See the file comment: when a manoeuvre's metrics are final.
inline constexpr double kQuietS = 10.0;
inline constexpr double kQuietDeg = 15.0;
inline constexpr double kFinalByS = 55.0;
/// Final manoeuvres a boat's wind estimate is made from (~3 h of racing).
inline constexpr std::size_t kMaxHistory = 200;
/// A live wind instrument's readings the boat's wind is the mean of (the review's: 2 minutes
/// either side of t0; live, the last 2 minutes), and how many are kept (10 Hz).
inline constexpr double kInstrumentWindS = 120.0;
inline constexpr std::size_t kMaxInstrumentReadings = 1200;

class ManoeuvreTracker {
 public:
  struct Config {
    double window_s = 90.0;
    double run_every_s = 2.0;
    double final_after_s = 25.0;
    double session_gap_s = 60.0;
    std::optional<double> wind_from_deg;  ///< given (a coach's); none: estimated (see above)
    std::size_t max_fixes = 1800;     ///< 90 s at 20 Hz
    std::size_t max_attitude = 4500;  ///< 90 s at 50 Hz
  };
  using Sink = std::function<void(const LiveManoeuvre&)>;

  explicit ManoeuvreTracker(Sink sink) : ManoeuvreTracker(std::move(sink), Config{}) {}
  ManoeuvreTracker(Sink sink, Config config);

  /// A boat's fix (COG, SOG): may run the detector and report to the sink.
  void on_fix(const FixSample& fix);
  /// A boat's attitude (heel, pitch).
  void on_attitude(const AttitudeSample& sample);
  /// A boat's wind instrument reading: with kMinWindReadings of the last kInstrumentWindS, the
  /// boat's manoeuvres are classified against it (the coach's wind still comes first).
  void on_wind(const WindSample& wind);
  /// Drops a boat's window and what was reported of it.
  void forget(const std::string& boat_id);
  /// Forgets every boat for which `known` is false.
  void retain(const std::function<bool(const std::string&)>& known);
  /// Frees a boat's window (a boat long silent: its next sample starts a new one), keeping what
  /// was reported of it.
  void release(const std::string& boat_id);

  [[nodiscard]] std::size_t boats() const { return boats_.size(); }
  /// Samples (fixes and attitude) held for a boat: its window.
  [[nodiscard]] std::size_t held(const std::string& boat_id) const;
  /// Detector runs so far (all boats).
  [[nodiscard]] std::uint64_t runs() const { return runs_; }

 private:
  struct Seen {
    double t0_s = 0.0;
    bool final = false;
    std::uint64_t run = 0;  ///< the run that last matched it: one manoeuvre per run
  };
  struct Boat {
    std::uint64_t base_ns = 0;  ///< the time base: the boat's first sample
    std::deque<fusion::CourseSample> course;
    std::deque<fusion::HeelSample> heel;
    bool trimmed = false;  ///< the window lost its oldest data: its start may cut a manoeuvre
    double next_run_s = 0.0;
    std::vector<Seen> seen;  ///< reported manoeuvres still in the window
    std::deque<fusion::Manoeuvre> history;  ///< final ones of the session, for the wind
    std::optional<double> wind_from_deg;    ///< estimated from `history`
    std::deque<std::pair<double, double>> instrument;  ///< (t_s, from_deg), the last minutes
  };
  Boat& boat(const std::string& id, std::uint64_t t_ns);
  void run(const std::string& id, Boat& b);

  Sink sink_;
  Config config_;
  std::unordered_map<std::string, Boat> boats_;
  std::vector<fusion::CourseSample> course_buf_;  ///< the window made contiguous, reused
  std::vector<fusion::HeelSample> heel_buf_;
  std::vector<double> instrument_buf_;
  std::uint64_t runs_ = 0;
};

/// The tracker in the shore: fed by the live worker, reporting to the dashboards as SSE events
/// of type `manoeuvre` (the REST row of /sessions/{id}/manoeuvres plus `boat_id` and `final`).
/// No session id: only the store's writer thread knows a boat's open session, and asking SQLite
/// from the live worker is what this replaces; the card needs none.
/// Fixes arrive on the DDS receive thread, which only queues them (queue_fix); the live worker
/// takes them once per batch of attitude samples and at least every kFixWakeup without one
/// (take_fixes), so the detector never runs on the receive thread.
class ManoeuvreLive {
 public:
  /// How often the live worker takes fixes when no attitude sample wakes it: far inside the 2 s
  /// of fixes between two runs of the detector.
  static constexpr std::chrono::milliseconds kFixWakeup{200};

  ManoeuvreLive(LiveHub& hub, const FleetModel& fleet, double session_gap_s);

  /// Any thread (the DDS listener): queues the fix for the live worker. Bounded: 5 s of a
  /// 1000-boat fleet at 10 Hz; beyond that the oldest are dropped, as the live view skips ahead.
  void queue_fix(const FixSample& fix);
  /// Live worker, once per batch of samples and at least every kFixWakeup without any: the fixes
  /// queued so far go to the tracker (a boat whose IMU has gone quiet still has its manoeuvres
  /// found). Boats the fleet model has forgotten are forgotten here too, and boats silent for
  /// longer than the window give back its memory (checked every minute).
  void take_fixes();
  /// Live worker: an attitude sample (heel and pitch through the turns).
  void on_attitude(const AttitudeSample& sample);
  /// Any thread (the DDS listener): queues a wind instrument reading, taken with the fixes.
  void queue_wind(const WindSample& wind);

 private:
  const FleetModel& fleet_;
  ManoeuvreTracker tracker_;
  std::mutex mutex_;
  std::vector<FixSample> inbox_;
  std::atomic<bool> has_fixes_{false};
  std::vector<FixSample> taken_;
  std::vector<WindSample> wind_inbox_, wind_taken_;
  std::chrono::steady_clock::time_point next_retain_{};
};

}  // namespace telltale::shore
