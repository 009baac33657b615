#pragma once
/// \file
/// The `race` IMU scenario's boat: the windward-leeward race of course.hpp as one rigid body, so
/// the IMU's heel, pitch and heading and the receiver's fixes are the same boat's.
///
///   auto course = std::make_shared<sim::RaceCourse>(seed);
///   auto sc = sim::make_race_scenario(course, seed, 25.0, 600.0);
///   while (sc->next(imu, truth)) {
///     const sim::CourseState fix = course->fix_at(imu.t_s);  // the same boat's receiver
///     ...
///   }
///   course->course().manoeuvres();  // the tacks and gybes it sailed
///
/// The course is stepped on its own 0.05 s grid (CourseSim::at at every step, whoever asks and
/// whenever), so what it sails depends on the seed alone: the scenario and a reader of fix_at()
/// see one race. The body follows a smoothed copy of it (see smooth_at).

#include <cstdint>
#include <deque>
#include <memory>

#include "telltale/fusion/sim/course.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::fusion::sim {

/// The course's boat on a time line both the IMU simulator and a GNSS reader can read.
class RaceCourse {
 public:
  static constexpr double kStepS = 0.05;  ///< CourseSim's own step: one receiver epoch each
  /// The smoothed motion's knots: every 5 steps (0.25 s); see smooth_at.
  static constexpr int kKnotSteps = 5;
  static constexpr double kKnotS = kStepS * kKnotSteps;
  /// How far back fix_at and smooth_at can still look from the furthest time stepped to.
  static constexpr double kHistoryS = 20.0;

  explicit RaceCourse(std::uint64_t seed, CourseParams params = {});

  /// Steps the course on until it has passed t_s (never back).
  void advance_to(double t_s);
  /// The receiver's epoch of the last step at or before t_s (t_s >= 0; steps on as needed; at
  /// most kHistoryS behind the furthest time stepped to). Its t_s is the step's time.
  [[nodiscard]] CourseState fix_at(double t_s);

  /// The boat's motion as the IMU simulator's body follows it, at t_s (after advance_to(t_s +
  /// 3 kKnotS)).
  struct Smooth {
    double heading_rad = 0.0;  ///< true, clockwise from north, continuous (not wrapped to 2 pi)
    double speed_m_s = 0.0;    ///< through the water = over ground (the course has no current)
    double heel_rad = 0.0;     ///< + starboard down
  };
  /// A uniform cubic B-spline through knots every kKnotS: C2, so the body's rates and
  /// accelerations are continuous (the course's helm switches its 20 deg/s turn on and off at
  /// once, which differentiated twice would be an infinite angular acceleration at the bow). Its
  /// kernel is symmetric (no lag) with a standard deviation of kKnotS / sqrt(3) = 0.14 s. Knots:
  /// the course's heading and heel at the knot's step (exact: the simulator's own), its speed as
  /// the mean of the receiver's speed over the 5 steps around it (CourseState keeps the true
  /// speed to itself; the mean takes the 0.05 m/s noise to 0.02 m/s). Before the start: the
  /// first knot.
  [[nodiscard]] Smooth smooth_at(double t_s) const;

  /// The simulator (its manoeuvres(), the wind).
  [[nodiscard]] const CourseSim& course() const { return sim_; }
  /// The mean true wind the course was set for, degrees (the waves run with it).
  [[nodiscard]] double mean_wind_from_deg() const { return sim_.params().wind_from_deg; }

 private:
  struct Step {
    CourseState state;
    double heading_deg = 0.0;  ///< unwrapped
  };
  void step();
  CourseSim sim_;
  std::int64_t next_step_ = 0;   ///< index of the next step to take
  std::int64_t first_step_ = 0;  ///< index of steps_.front()
  std::deque<Step> steps_;
  std::int64_t first_knot_ = 0;  ///< index of knots_.front()
  std::deque<Smooth> knots_;
};

/// The `race` scenario on a given course (the boat node shares it with its simulated receiver).
/// Its seed draws the waves and the sensor errors; the course has its own (pass the same).
/// duration_s <= 0: endless. See scenario.hpp's list for what it is.
[[nodiscard]] std::unique_ptr<ImuScenario> make_race_scenario(std::shared_ptr<RaceCourse> course,
                                                              std::uint64_t seed, double rate_hz,
                                                              double duration_s,
                                                              const ScenarioOptions& options = {});

}  // namespace telltale::fusion::sim
