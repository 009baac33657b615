// The race scenario (race.hpp): the IMU's boat is the course's boat. Its heel flips to leeward at
// every tack and gybe the course sails, its heading and GNSS are the course's, and the production
// filter, fed that GNSS speed as the boat node feeds it, follows its heel through a whole race.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "telltale/fusion/attitude_speed.hpp"
#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/sim/race.hpp"

namespace telltale::fusion::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kRaceS = 600.0;

struct Sailed {
  std::vector<double> t_s, heel_deg, course_heel_deg;
  std::vector<TruthManoeuvre> manoeuvres;
  /// Mean of v over [from_s, to_s).
  [[nodiscard]] double mean(const std::vector<double>& v, double from_s, double to_s) const {
    double s = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < t_s.size(); ++i)
      if (t_s[i] >= from_s && t_s[i] < to_s) s += v[i], ++n;
    return n ? s / n : std::nan("");
  }
};

Sailed sail(std::uint64_t seed) {
  auto course = std::make_shared<RaceCourse>(seed);
  auto sc = make_race_scenario(course, seed, 25.0, kRaceS);
  Sailed r;
  ImuSample imu;
  AttitudeTruth truth;
  while (sc->next(imu, truth)) {
    r.t_s.push_back(truth.t_s);
    r.heel_deg.push_back(truth.heel_rad / kDeg);
    r.course_heel_deg.push_back(course->fix_at(truth.t_s).heel_deg);
  }
  r.manoeuvres = course->course().manoeuvres();
  return r;
}

// Given three boats racing 10 minutes (a beat, the windward mark, the run), when each tack and
// gybe the course logs is looked at, then the body's heel is on one side over the 5 s before
// the turn and on the other over the 5 s after it settles, by more than the waves' roll, and on
// the course's leeward side both times (a heel of the wrong sign flips too: it is on the
// wrong side). Seen failing with the body's heel taken as -heel (not to leeward at every tack)
// and as |heel| (no flip: 11.3 -> 15.2 deg through seed 1's first tack).
TEST(RaceScenario, TruthHeelFlipsToLeewardAtEveryTackAndGybe) {
  int tacks = 0, gybes = 0;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Sailed r = sail(seed);
    for (const auto& m : r.manoeuvres) {
      if (m.kind != TruthKind::kTack && m.kind != TruthKind::kGybe) continue;
      if (m.end_s + 8.0 > kRaceS) continue;
      (m.kind == TruthKind::kTack ? tacks : gybes)++;
      const double before = r.mean(r.heel_deg, m.start_s - 6.0, m.start_s - 1.0);
      const double after = r.mean(r.heel_deg, m.end_s + 3.0, m.end_s + 8.0);
      const double course_before = r.mean(r.course_heel_deg, m.start_s - 6.0, m.start_s - 1.0);
      const double course_after = r.mean(r.course_heel_deg, m.end_s + 3.0, m.end_s + 8.0);
      const std::string what = std::string(to_string(m.kind)) + " at " + std::to_string(m.t_s) +
                               " s, seed " + std::to_string(seed);
      EXPECT_LT(before * after, 0.0) << what << ": " << before << " -> " << after;
      EXPECT_GT(std::abs(before), 3.0) << what;
      EXPECT_GT(std::abs(after), 3.0) << what;
      EXPECT_GT(before * course_before, 0.0) << what << ": not to leeward before";
      EXPECT_GT(after * course_after, 0.0) << what << ": not to leeward after";
    }
  }
  EXPECT_GE(tacks, 6);
  EXPECT_GE(gybes, 2);
}

// Given the race, its attitude's heading and its receiver's speed and course are the course's:
// the heading within the waves' yaw and the smoothing, the speed and course over ground within
// the waves' surge and sway and the receiver's noise and latency. Seen failing with the body's
// yaw turning against the course (179 deg off).
TEST(RaceScenario, HeadingAndGnssAreTheCoursesBoat) {
  auto course = std::make_shared<RaceCourse>(4);
  auto sc = make_race_scenario(course, 4, 25.0, 300.0);
  ImuSample imu;
  AttitudeTruth truth;
  double max_heading_deg = 0.0, se_sog = 0.0, se_cog = 0.0;
  int fixes = 0;
  while (sc->next(imu, truth)) {
    const CourseState c = course->fix_at(truth.t_s);
    const double heading = 90.0 - truth.yaw_rad / kDeg;
    max_heading_deg =
        std::max(max_heading_deg, std::abs(std::remainder(heading - c.heading_deg, 360.0)));
    if (const auto& f = sc->gnss_fix()) {
      // The fix left the receiver 0.1 s before it arrived.
      const CourseState then = course->fix_at(truth.t_s - 0.1);
      se_sog += (f->sog_m_s - then.sog_m_s) * (f->sog_m_s - then.sog_m_s);
      const double dc = std::remainder(f->cog_deg - then.heading_deg, 360.0);
      se_cog += dc * dc;
      ++fixes;
    }
  }
  ASSERT_GT(fixes, 1000);
  EXPECT_LT(max_heading_deg, 5.0);
  EXPECT_LT(std::sqrt(se_sog / fixes), 0.3);
  EXPECT_LT(std::sqrt(se_cog / fixes), 6.0);
}

// Given three boats racing 10 minutes with the calibrated sensors' errors, when the production
// filter runs on the IMU with the scenario's GNSS speed and course held as the boat node holds
// them, then its heel follows the truth: within 0.5 deg RMS and 2 deg at worst, tacks and gybes
// included (scored from 15 s: it starts under way). Measured 0.23-0.28 RMS, 0.96-1.09 max. Seen
// failing with the centripetal acceleration taken out of the simulated body's (0.74-0.99 RMS,
// 4.2-5.1 max: the filter takes off a speed x turn rate the sensor never felt) and with the
// body's yaw turning against its track (1.3-1.8 RMS, 7.9-11 max).
TEST(RaceScenario, ProductionFilterTracksTheHeelThroughARace) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    auto sc = make_scenario("race", seed, 25.0, kRaceS);
    ASSERT_NE(sc, nullptr);
    TelltaleAttitudeFilter f;
    GroundSpeedHold speed;
    ImuSample imu;
    AttitudeTruth truth;
    double se = 0.0, worst = 0.0, worst_t = 0.0;
    int n = 0;
    while (sc->next(imu, truth)) {
      if (const auto& fix = sc->gnss_fix()) speed.on_fix(fix->t_s, fix->sog_m_s, fix->cog_deg);
      f.set_speed(speed.speed_m_s(imu.t_s), speed.rate_m_s2(imu.t_s),
                  speed.cog_rate_rad_s(imu.t_s));
      f.update(imu);
      if (truth.t_s < sc->warmup_s()) continue;
      const double e = std::abs(f.output().heel_rad - truth.heel_rad) / kDeg;
      se += e * e;
      ++n;
      if (e > worst) worst = e, worst_t = truth.t_s;
    }
    const double rms = std::sqrt(se / n);
    RecordProperty("seed" + std::to_string(seed) + "_rms_deg", std::to_string(rms));
    EXPECT_LT(rms, 0.5) << "seed " << seed;
    EXPECT_LT(worst, 2.0) << "seed " << seed << " at " << worst_t << " s";
  }
}

}  // namespace
}  // namespace telltale::fusion::sim
