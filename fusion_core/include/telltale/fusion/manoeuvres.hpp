#pragma once
/// \file
/// Tacks, gybes and other manoeuvres found in a boat's course and measured. Pure.
///
/// Input: time-ordered GNSS samples (COG, SOG; a heading when a compass gives one) and
/// optionally attitude samples (heel, pitch). Everything is put on a 10 Hz grid (the latest
/// sample at or before each tick, not older than 1 s; older: a gap).
///
/// **Detection.** The helm's turns first: runs of ticks whose course rate (1 s central difference)
/// has one sign and exceeds 2 deg/s (dips of 0.3 s bridged), padded by 0.5 s to steady course.
/// A turn is a manoeuvre where the circular-mean course over the `window_s` (10 s) before it
/// starts and after it ends differs by >= `min_turn_deg` (60), at a mean SOG >= 1 m/s before it:
/// the rule "10 s before and after t" with the turn itself taken out of the windows, so a 64 deg
/// gybe taking 3 s reads 64 (windows about one tick read it 8-10 deg short and missed it). Two
/// turns of one sign with less than 3 s between their turning are one manoeuvre (a pause),
/// unless each is a manoeuvre on its own, each window cut where the other turns: a tack on the
/// layline 2 s before the mark and the rounding are two, each measured on its own. Turns of
/// opposite signs are never one; turns under a quarter of `min_turn_deg` are course keeping.
///
/// **Classification** against the true wind W: the course before (mean over the 10 s before the
/// turn) turned through the unwrapped turn: crossing head-to-wind once is a tack, crossing
/// dead downwind a gybe; >= `penalty_deg` (300) of continuous turning is a penalty turn; a turn
/// that crosses neither is a bear-away (ending further off the wind) or a round-up. With heel,
/// a tack or gybe is checked against the heel flip (`heel_flip_agrees`), never overruled by it.
///
/// **Wind without a sensor.** The bisector of a tack (the course halfway through the turn) is
/// the wind direction; a gybe's, inverted. First the axis: the circular median of the doubled
/// bisectors of the turns of 50-140 deg. Then which end is upwind, from how the boat sailed on the
/// steady courses either side of the turns each end would call tacks and gybes: more heel (the
/// apparent wind is the true wind plus the boat's speed close-hauled, minus it running), else
/// less speed (close-hauled is every polar's slowest point of sail). Tack and gybe angles do not
/// tell them apart (an asymmetric-spinnaker boat gybes through as much as it tacks); only when
/// every turn is of one kind is the end taken where tacks turn more than 72 deg. Then, with the
/// manoeuvres classified, the wind is the circular median of the tacks' bisectors and the gybes'
/// inverted (twice: classify again with it), reported with its uncertainty (1.25 x 1.4826 MAD /
/// sqrt(n), the median's standard error) and as it stood after each tack or gybe
/// (`wind_over_time`). A direction given by the caller overrides it; a wind instrument's
/// readings (`wind_at`) override it per manoeuvre, at its t0.
///
/// **Metrics** (t0 = the course crosses the bisector of the mean courses 20-5 s before and 5-20 s
/// after the turn; a penalty turn's t0 is half its turning done). All windows relative to t0:
///  - turn_deg: mean course (5, 20) after minus (-20, -5) before, unwrapped through the turn,
///    absolute; turn_dir +1 clockwise (to starboard), -1 anticlockwise. In practice the 15 s of
///    steady course before the turn's start and after its end (the continuous turn above), cut
///    short where the neighbouring manoeuvre's turn begins (a layline tack 8 s before the mark).
///  - entry_sog: mean SOG (-20, -10); min_sog: minimum SOG (-5, +15); exit_sog: mean (15, 25);
///    speed_loss = entry - min.
///  - turn_duration_s: from 10 % to 90 % of the turn (the unwrapped course between the two means).
///  - recovery_s: from t0 until SOG is back to 90 % of entry after the minimum (NaN: not within
///    60 s). max_turn_rate: largest |course rate| (1 s central difference) in (-10, +10);
///    mean_turn_rate = 80 % of the turn / turn_duration.
///  - distance_lost_m (wind-free, after SAP Sailing Analytics): u = the mean course (bisector;
///    a penalty turn: the course before); the entry velocity (mean velocity vector (-20, -10))
///    projected on u and extrapolated over [t0-10, t0+20] (30 s), minus the distance actually
///    made along u in that window (velocity from SOG and COG integrated).
///  - vmg_lost_m (needs the wind): the same against the wind: w = towards the wind when the entry
///    was upwind (|TWA| < 90), else downwind; entry VMG x 30 s minus the distance made along w.
///  - heel: heel_peak_deg the largest |heel| in (-10, +10), signed (+ starboard);
///    heel_peak_leeward/windward_deg the largest heel to the exit tack's leeward / windward side
///    (the exit side: sign of the mean heel (5, 20)); heel_zero_s the heel's sign change nearest
///    t0 in (-10, +10), relative to t0; exit_heel_deg mean (15, 25).
///  - pitch: min, max, mean in (-5, +10).
///  - unsteady_entry: the course's circular SD (-20, -5) above 8 deg, or SOG varying by more than
///    20 % of its mean (-20, -10): the loss may come from before the turn (flagged, not clipped).
/// A window without data gives NaN.

#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace telltale::fusion {

struct CourseSample {
  double t_s = 0.0;
  double cog_deg = 0.0;      ///< NaN when unknown
  double sog_m_s = 0.0;      ///< NaN when unknown
  double heading_deg = std::numeric_limits<double>::quiet_NaN();  ///< used as the course if given
};

struct HeelSample {
  double t_s = 0.0;
  double heel_deg = 0.0;  ///< + to starboard
  double pitch_deg = 0.0;
};

enum class ManoeuvreKind { kTack, kGybe, kBearAway, kRoundUp, kPenalty, kOther };
const char* to_string(ManoeuvreKind k);

struct ManoeuvreOptions {
  std::optional<double> wind_from_deg;  ///< a wind instrument or the coach: overrides the estimate
  /// The wind at a time (s, the samples' time base), where a wind instrument measured it: each
  /// manoeuvre is classified and its VMG loss measured against the wind of its t0 (a shift of 20
  /// deg over a session moves a tack's VMG loss by a third of its distance); nullopt at a time
  /// it does not know falls back to the session's wind.
  std::function<std::optional<double>(double t_s)> wind_at;
  double min_turn_deg = 60.0;
  double window_s = 10.0;
  double min_sog_m_s = 1.0;
  double penalty_deg = 300.0;
};

struct Manoeuvre {
  ManoeuvreKind kind = ManoeuvreKind::kOther;
  double t0_s = 0.0;
  double turn_deg = 0.0;
  int turn_dir = 0;
  double course_before_deg = 0.0, course_after_deg = 0.0, bisector_deg = 0.0;
  double entry_sog_m_s = 0.0, min_sog_m_s = 0.0, exit_sog_m_s = 0.0, speed_loss_m_s = 0.0;
  double turn_duration_s = 0.0, recovery_s = 0.0;
  double max_turn_rate_deg_s = 0.0, mean_turn_rate_deg_s = 0.0;
  double distance_lost_m = 0.0, vmg_lost_m = 0.0;
  double heel_peak_deg = 0.0, heel_peak_windward_deg = 0.0, heel_peak_leeward_deg = 0.0;
  double heel_zero_s = 0.0, exit_heel_deg = 0.0;
  double pitch_min_deg = 0.0, pitch_max_deg = 0.0, pitch_mean_deg = 0.0;
  std::optional<bool> heel_flip_agrees;  ///< tack/gybe with heel: did the heel change side?
  bool unsteady_entry = false;
  double entry_course_sd_deg = 0.0;
};

struct WindPoint {
  double t_s = 0.0;
  double from_deg = 0.0;
  double uncertainty_deg = 0.0;
  int n = 0;  ///< tacks and gybes behind it
};

struct ManoeuvreSummary {
  ManoeuvreKind kind;
  int count = 0;
  double mean_lost_m = 0.0, best_lost_m = 0.0, worst_lost_m = 0.0;  ///< NaN without any
};

struct ManoeuvreReport {
  std::vector<Manoeuvre> manoeuvres;
  std::optional<double> wind_from_deg;  ///< NaN-free when known (given or estimated)
  double wind_uncertainty_deg = 0.0;    ///< 0 when given
  bool wind_given = false;
  std::vector<WindPoint> wind_over_time;
};

/// Finds, classifies and measures the manoeuvres (see the file comment). `course` and `heel`
/// must be time-ordered (same time base).
ManoeuvreReport analyse_manoeuvres(std::span<const CourseSample> course,
                                   std::span<const HeelSample> heel,
                                   const ManoeuvreOptions& options = {});

/// The wind (from) as analyse_manoeuvres estimates it, from manoeuvres it has already measured:
/// a live boat's so far, passed back as `wind_from_deg` so that a short window of data is
/// classified against the session's wind, not against its own one or two turns. nullopt
/// without a turn of 50-140 deg.
std::optional<double> estimate_wind(std::span<const Manoeuvre> list);

/// Per kind (those present): count and distance lost (mean, best = least, worst = most).
std::vector<ManoeuvreSummary> summarise(const std::vector<Manoeuvre>& list);

}  // namespace telltale::fusion
