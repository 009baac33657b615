#pragma once
/// \file
/// A boat sailing a windward-leeward race: the simulated GNSS course of `boat_node --source sim`
/// and the ground truth the manoeuvre detector is evaluated against. Pure (std only).
///
/// The wind shifts (two slow oscillations, +-8 deg) and gusts; the boat beats at 42 deg to the
/// true wind, tacking on the layline to the windward mark, and runs at 135-148 deg (per boat), gybing on
/// the layline to the leeward mark; speed from a simple polar scaled by a per-boat factor, halved
/// through a tack or gybe and recovering over ~8 s. Every boat differs by its seed: start line
/// position, speed factor, wind phase as it sees it, first tack.
///
/// `drills` (off by default, so `boat_node` boats sail exactly as before) adds, per seed, a
/// bear-away on a beat (to 120 deg off the wind for 40 s, then back up: a bear-away and a
/// round-up) and a penalty turn (a 720) on some leg, drawn from their own random stream so the
/// race's own draws are unchanged.
///
/// Heel: a simple model for the detector's heel checks only (the IMU simulator of boat_node
/// runs its own scenario): positive to starboard; the boat heels to leeward, 14 deg upwind and
/// 5 deg downwind at 6 m/s, scaled with the wind, following with a 1 s lag (so it flips through
/// a tack or gybe).

#include <cstdint>
#include <random>
#include <vector>

namespace telltale::fusion::sim {

struct CourseParams {
  double origin_lat_deg = 54.3440;  ///< leeward mark (Kiel outer fjord: open water)
  double origin_lon_deg = 10.1900;
  double leg_m = 600.0;             ///< leeward to windward mark
  double wind_from_deg = 255.0;     ///< mean true wind direction
  double wind_m_s = 6.0;            ///< mean true wind speed
  bool drills = false;              ///< add a bear-away and a 720 (see the file comment)
};

/// What the receiver reports (position with its wandering error, SOG and COG with noise) and
/// what the simulator knows (true heading, wind, heel).
struct CourseState {
  double t_s = 0.0;
  double lat_deg = 0.0, lon_deg = 0.0;
  double sog_m_s = 0.0;
  double cog_deg = 0.0;
  double heading_deg = 0.0;  ///< true heading, no noise
  double wind_from_deg = 0.0;
  double wind_m_s = 0.0;
  double heel_deg = 0.0;     ///< + to starboard
  double east_m = 0.0, north_m = 0.0;  ///< true position from the leeward mark (no receiver error)
  bool upwind = true;
};

enum class TruthKind { kTack, kGybe, kRounding, kBearAway, kRoundUp, kPenalty };
const char* to_string(TruthKind k);

/// One manoeuvre as the simulator sailed it.
struct TruthManoeuvre {
  TruthKind kind = TruthKind::kTack;
  double t_s = 0.0;  ///< the bow crosses the wind (tack, gybe, a rounding with either); else
                     ///< half the turn done
  double turn_deg = 0.0;  ///< signed heading change start to end (+ clockwise), steady to steady
  double start_s = 0.0, end_s = 0.0;
  double wind_from_deg = 0.0;  ///< the wind then
  int crossed = 0;             ///< the bow crossed the wind: 0 no, 1 head to wind, 2 dead downwind
};

class CourseSim {
 public:
  CourseSim(std::uint64_t seed, CourseParams p = {});
  /// Advances to `t_s` (seconds since start, increasing) and returns the receiver's epoch then.
  CourseState at(double t_s);
  [[nodiscard]] double wind_from_deg() const { return wind_from_deg_; }
  [[nodiscard]] bool upwind() const { return upwind_; }
  [[nodiscard]] int tacks() const { return tacks_; }
  /// The manoeuvres completed so far (a turn still under way is not listed yet).
  [[nodiscard]] const std::vector<TruthManoeuvre>& manoeuvres() const { return log_; }
  [[nodiscard]] const CourseParams& params() const { return p_; }

 private:
  void step(double dt);
  void begin(TruthKind kind);
  void track_turn(double turn, double dt, double err);
  CourseParams p_;
  std::mt19937_64 rng_;
  double t_s_ = 0.0;
  double x_m_ = 0.0, y_m_ = 0.0;  ///< east, north of the leeward mark
  double heading_deg_ = 0.0;
  double speed_m_s_ = 0.0;
  double factor_ = 1.0;
  double phase1_ = 0.0, phase2_ = 0.0;
  double gust_ = 0.0;
  double tws_ = 0.0;
  double wind_from_deg_ = 0.0;
  double heel_deg_ = 0.0;
  bool upwind_ = true;
  double downwind_twa_deg_ = 150.0;  ///< its running angle to the true wind, per boat
  double corridor_deg_ = 20.0;    ///< how far off the axis the mark may bear before a tack
  int side_ = 1;                  ///< +1 starboard tack (wind over the starboard side), -1 port
  double manoeuvre_s_ = 1e9;      ///< time since the last tack or gybe
  int tacks_ = 0;
  double last_fix_s_ = 0.0;
  double err_e_m_ = 0.0, err_n_m_ = 0.0;  ///< the receiver's slowly wandering position error

  // Drills (their own random stream) and the ground-truth log.
  std::mt19937_64 drill_rng_;
  double bear_at_s_ = 1e18, penalty_at_s_ = 1e18;
  double bear_left_s_ = 0.0;      ///< > 0: bearing away, seconds left before heading back up
  double spin_left_deg_ = 0.0;    ///< > 0: in the 720, degrees still to turn
  int spin_dir_ = 1;
  double drill_quiet_s_ = 1e9;    ///< since a drill ended (no tack right after it)
  struct Open {
    bool active = false;
    TruthKind kind = TruthKind::kTack;
    double start_s = 0.0, turned = 0.0, cross_s = -1.0;
    int crossed = 0;
    double prev_rel = 0.0;
    std::vector<std::pair<double, double>> path;  ///< (t, turned)
  } open_;
  std::vector<TruthManoeuvre> log_;
};

}  // namespace telltale::fusion::sim
