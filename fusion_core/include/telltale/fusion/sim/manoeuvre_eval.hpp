#pragma once
/// \file
/// The manoeuvre detector (manoeuvres.hpp) against the race simulator's ground truth
/// (course.hpp, with drills: bear-aways and 720s): `fusion_cli manoeuvre-eval` and the tests.
///
/// Per seed: `minutes` of the course at 10 Hz (COG, SOG; heel from the simulator's heel model),
/// analysed without a wind (estimated). A detected manoeuvre matches a true one of its kind
/// within `match_s` of t0 (true: the bow crossing the wind, or half the turn done). Mark
/// roundings are bear-aways / round-ups in the truth's terms, but a rounding next to a tack on
/// the layline merges with it (one turn of up to ~190 deg): a detection matching a rounding is
/// not scored as a false tack or gybe. Turn angle error: |detected - true| for matched tacks and
/// gybes. Wind error: the final estimate against the simulator's mean wind (255 deg).
/// Distance lost error: |detected - true| for matched tacks and gybes, the truth by the same
/// definition (manoeuvres.hpp) on the simulator's own motion: its true positions (no receiver
/// error), its t0, and the bisector of its true courses at the turn's start and end.

#include <cstdint>
#include <string>
#include <vector>

#include "telltale/fusion/manoeuvres.hpp"

namespace telltale::fusion::sim {

struct KindScore {
  int truth = 0, detected = 0, matched = 0;
  [[nodiscard]] double recall() const { return truth ? double(matched) / truth : 1.0; }
  [[nodiscard]] double precision() const { return detected ? double(matched) / detected : 1.0; }
};

struct ManoeuvreEval {
  KindScore tack, gybe, bear_away, round_up, penalty;
  int roundings = 0;               ///< true roundings (not scored)
  double turn_err_mean_deg = 0.0, turn_err_max_deg = 0.0;
  double wind_err_mean_deg = 0.0, wind_err_max_deg = 0.0;
  double t0_err_mean_s = 0.0;
  double lost_err_mean_m = 0.0, lost_err_max_m = 0.0;
  std::vector<std::string> misses;  ///< misses, false detections, turn errors > 5 deg
};

/// `with_heel` false: the course alone, as from a GNSS-only log (the wind's upwind end from speed).
ManoeuvreEval evaluate_manoeuvres(std::uint64_t first_seed, int seeds, double minutes,
                                  const ManoeuvreOptions& options = {}, double match_s = 10.0,
                                  bool with_heel = true);

}  // namespace telltale::fusion::sim
