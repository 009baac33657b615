// StepClock (pdr/step_clock.hpp): how many steps each event of the phone's two detectors stands
// for, case by case, on hand-made event streams; and Cadence, the foot pipeline's part of it.
#include "telltale/fusion/pdr/step_clock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

namespace telltale::fusion {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;

/// The phone's recent samples at 50 Hz over [t0, t1): walking (|f| swinging by 2 m/s^2 at
/// `period_s`, turning at 1 rad/s) or standing (still: g, no rotation).
void push_samples(RecentSamples& recent, double t0, double t1, bool walking,
                  double period_s = 0.5) {
  for (double t = t0; t < t1 - 1e-9; t += 0.02) {
    ImuSample s;
    s.t_s = t;
    const double swing = walking ? 2.0 * std::sin(2.0 * M_PI * t / period_s) : 0.0;
    s.acc_body_m_s2 = Eigen::Vector3d(0.0, 0.0, kG + swing);
    s.gyro_body_rad_s = Eigen::Vector3d(walking ? 1.0 : 0.0, 0.0, 0.0);
    recent.push(s);
  }
}

RecentSamples make_recent() { return RecentSamples(StandLimits{0.6, 0.2, 0.3}); }

PhoneEvents acc_event(double t) {
  PhoneEvents e;
  e.t_s = t;
  e.by_acc = true;
  return e;
}

PhoneEvents swing_event(double t, bool recognised, double step_t) {
  PhoneEvents e;
  e.t_s = t;
  e.by_swing = true;
  e.swing = recognised;
  e.swing_step_t_s = step_t;
  e.half_swing_s = 0.5;
  return e;
}

constexpr double kWalkEnergy = 1.0;  // above gap_min_energy: the phone moves like a walk

/// Steps at t0, t0 + 0.5, ... (n of them) by the acceleration, while walking.
void walk(StepClock& clock, RecentSamples& recent, double t0, int n) {
  for (int i = 0; i < n; ++i) {
    const double t = t0 + 0.5 * i;
    push_samples(recent, t - 0.5, t, true);
    ASSERT_TRUE(clock.at_events(acc_event(t), recent, kWalkEnergy)) << t;
  }
}

// Given events every 0.5 s by the acceleration, each is one step at its own time, chained to
// the one before, and the cadence is 0.5 s once measured.
TEST(StepClock, ASteadyWalkIsOneStepPerEvent) {
  StepClock clock(StepClockParams{});
  RecentSamples recent = make_recent();
  std::optional<ClockStep> prev;
  for (int i = 0; i < 8; ++i) {
    const double t = 1.0 + 0.5 * i;
    push_samples(recent, t - 0.5, t, true);
    const auto step = clock.at_events(acc_event(t), recent, kWalkEnergy);
    ASSERT_TRUE(step);
    EXPECT_DOUBLE_EQ(step->t_s, t);
    EXPECT_EQ(step->extra, 0);
    EXPECT_DOUBLE_EQ(step->prev_t_s, prev ? prev->t_s : -1.0);
    prev = step;
  }
  EXPECT_DOUBLE_EQ(clock.cadence().interval_s(), 0.5);
  // No event, no step.
  EXPECT_FALSE(clock.at_events(PhoneEvents{}, recent, kWalkEnergy));
}

// Given a walk at 0.5 s, when the next event comes 1.5 s after the last (three intervals) while
// the phone kept moving like a walk, then it stands for three steps; the same gap with the phone
// hardly moving (a stop) is one step; neither gap is taken for the cadence.
TEST(StepClock, AGapWalkedHoldsTheMissedStepsAndAStopHoldsNone) {
  for (const double energy : {kWalkEnergy, 0.1}) {
    StepClock clock(StepClockParams{});
    RecentSamples recent = make_recent();
    walk(clock, recent, 1.0, 6);  // last step at 3.5
    push_samples(recent, 3.5, 5.0, true);
    const auto step = clock.at_events(acc_event(5.0), recent, energy);
    ASSERT_TRUE(step);
    EXPECT_EQ(step->extra, energy > 0.5 ? 2 : 0) << energy;
    EXPECT_DOUBLE_EQ(step->prev_t_s, 3.5);
    EXPECT_DOUBLE_EQ(clock.cadence().interval_s(), 0.5) << energy;
  }
}

// Given a walk, then a stand (the phone still for a second), when the hand moves the phone once
// (a lone event), then it is held and counts nothing; when the walk resumes, its first event is
// held until the second confirms it within two intervals, and the second counts both.
TEST(StepClock, AWalkAfterAStandStartsOnlyWhenASecondEventConfirmsIt) {
  StepClock clock(StepClockParams{});
  RecentSamples recent = make_recent();
  walk(clock, recent, 1.0, 6);  // last step at 3.5
  push_samples(recent, 3.5, 5.0, false);
  push_samples(recent, 5.0, 5.3, true);
  EXPECT_FALSE(clock.at_events(acc_event(5.3), recent, kWalkEnergy));  // the lone event
  push_samples(recent, 5.3, 6.5, false);  // still again: no walk followed it
  push_samples(recent, 6.5, 7.0, true);
  EXPECT_FALSE(clock.at_events(acc_event(7.0), recent, kWalkEnergy));  // the walk's first, held
  push_samples(recent, 7.0, 7.5, true);
  const auto step = clock.at_events(acc_event(7.5), recent, kWalkEnergy);
  ASSERT_TRUE(step);
  EXPECT_EQ(step->extra, 1);  // the held first event
  EXPECT_DOUBLE_EQ(step->prev_t_s, 3.5);
  // Nor is the interval across the stand a cadence: after a walk of three intervals (0.5 s, the
  // fewest that make a cadence) and a short stand, the confirmed restart leaves it at 0.5 s.
  StepClock short_walk(StepClockParams{});
  RecentSamples recent_short = make_recent();
  walk(short_walk, recent_short, 1.0, 4);  // steps at 1.0 .. 2.5
  push_samples(recent_short, 2.5, 3.3, false);
  push_samples(recent_short, 3.3, 3.5, true);
  EXPECT_FALSE(short_walk.at_events(acc_event(3.5), recent_short, kWalkEnergy));
  push_samples(recent_short, 3.5, 4.0, true);
  ASSERT_TRUE(short_walk.at_events(acc_event(4.0), recent_short, kWalkEnergy));
  EXPECT_DOUBLE_EQ(short_walk.cadence().interval_s(), 0.5);
  // Off (walk_start_intervals 0), the first event after the stand is a step at once.
  StepClock off(StepClockParams{.walk_start_intervals = 0.0});
  RecentSamples recent_off = make_recent();
  walk(off, recent_off, 1.0, 6);
  push_samples(recent_off, 3.5, 5.0, false);
  push_samples(recent_off, 5.0, 5.3, true);
  EXPECT_TRUE(off.at_events(acc_event(5.3), recent_off, kWalkEnergy));
}

// Given steps counted by the acceleration, when the phone starts to swing and the arm's turn
// marks the last step again 0.1 s later, then that is the same step (none); the next turn a full
// interval later is one step at the turn's own time, and the interval across the handoff (two
// detectors marking a step at different moments) is not taken for the cadence.
TEST(StepClock, AHandoffBetweenTheDetectorsCountsTheSameStepOnce) {
  StepClock clock(StepClockParams{});
  RecentSamples recent = make_recent();
  walk(clock, recent, 1.0, 4);  // steps at 1.0 .. 2.5: a cadence of 0.5 s
  push_samples(recent, 2.5, 2.6, true);
  EXPECT_FALSE(clock.at_events(swing_event(2.6, true, 2.55), recent, kWalkEnergy));
  push_samples(recent, 2.6, 3.1, true);
  const auto step = clock.at_events(swing_event(3.1, true, 3.05), recent, kWalkEnergy);
  ASSERT_TRUE(step);
  EXPECT_DOUBLE_EQ(step->t_s, 3.05);
  EXPECT_EQ(step->extra, 0);
  // The cadence is still the walk's, not the 0.55 s across the handoff.
  EXPECT_DOUBLE_EQ(clock.cadence().interval_s(), 0.5);
  // While the phone swings the acceleration's events are not steps.
  push_samples(recent, 3.1, 3.3, true);
  PhoneEvents acc_while_swinging = acc_event(3.3);
  acc_while_swinging.swing = true;
  EXPECT_FALSE(clock.at_events(acc_while_swinging, recent, kWalkEnergy));
}

// Given a walk that starts with the arm swinging, when the swing is recognised at its third
// turn (the acceleration having found no step), then that step counts the two turns before it.
TEST(StepClock, ASwingingStartCountsTheTurnsBeforeTheSwingWasRecognised) {
  StepClock clock(StepClockParams{});
  RecentSamples recent = make_recent();
  push_samples(recent, 0.0, 1.0, true);
  EXPECT_FALSE(clock.at_events(swing_event(1.0, false, 0.95), recent, kWalkEnergy));
  push_samples(recent, 1.0, 1.5, true);
  EXPECT_FALSE(clock.at_events(swing_event(1.5, false, 1.45), recent, kWalkEnergy));
  push_samples(recent, 1.5, 2.0, true);
  const auto step = clock.at_events(swing_event(2.0, true, 1.95), recent, kWalkEnergy);
  ASSERT_TRUE(step);
  EXPECT_EQ(step->extra, 2);
  EXPECT_DOUBLE_EQ(step->t_s, 1.95);
  // Only at the walk's start: the next turn is one step.
  push_samples(recent, 2.0, 2.5, true);
  const auto next = clock.at_events(swing_event(2.5, true, 2.45), recent, kWalkEnergy);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->extra, 0);
}

// Given a cadence that is wrong (0.5 s, where the phone's acceleration repeats every 1.0 s and
// every event fills one step into its gap), when eleven gaps in a row have been filled and the
// acceleration does not repeat at the cadence, then the cadence is forgotten and learnt again
// from the events: the steps stop doubling.
TEST(StepClock, ACadenceThatFillsEveryGapIsLearntAgain) {
  StepClock clock(StepClockParams{});
  RecentSamples recent = make_recent();
  walk(clock, recent, 1.0, 6);  // cadence 0.5, last step at 3.5
  int filled = 0;
  int after_reset = 0;
  for (int i = 1; i <= 16; ++i) {
    const double t = 3.5 + 1.0 * i;
    push_samples(recent, t - 1.0, t, true, 1.0);
    const auto step = clock.at_events(acc_event(t), recent, kWalkEnergy);
    ASSERT_TRUE(step);
    if (i <= 10) {
      EXPECT_EQ(step->extra, 1) << t;
      filled += step->extra;
    } else {
      after_reset += step->extra;
    }
  }
  EXPECT_EQ(filled, 10);
  EXPECT_EQ(after_reset, 0);
  EXPECT_DOUBLE_EQ(clock.cadence().interval_s(), 1.0);
}

// Cadence: a foot's stride events (two steps each) 1.1 s apart give a 0.55 s step; intervals
// shorter than the floor or of 2 s and more are no cadence; the median shrugs off one outlier.
TEST(Cadence, MedianOfTheLastIntervalsPerStep) {
  Cadence c(0.2);
  EXPECT_DOUBLE_EQ(c.interval_s(), 0.0);
  EXPECT_LT(c.last_step_t_s(), 0.0);
  for (int i = 0; i < 4; ++i) c.at_step(1.1 * i, 2.0, true);
  EXPECT_NEAR(c.interval_s(), 0.55, 1e-12);
  c.at_step(3.3 + 0.3, 2.0, true);  // 0.15 s per step: under the floor
  c.at_step(3.6 + 5.0, 2.0, true);  // 2.5 s per step: a pause
  EXPECT_NEAR(c.interval_s(), 0.55, 1e-12);
  c.at_step(8.6 + 1.6, 2.0, true);  // one 0.8 s step among 0.55 s ones
  EXPECT_NEAR(c.interval_s(), 0.55, 1e-12);
  c.at_step(12.0, 1.0, false);  // not learnt, but the last step
  EXPECT_DOUBLE_EQ(c.last_step_t_s(), 12.0);
  c.forget();
  EXPECT_DOUBLE_EQ(c.interval_s(), 0.0);
  EXPECT_DOUBLE_EQ(c.last_step_t_s(), 12.0);
}

// Given a walk whose first two events are one step detected twice (0.2 s apart, as on a real
// lower-back recording), then that interval alone is no cadence (it read 300 steps/min, and the
// body PDR laid each of the next ten steps twice, 1.9 m each); two more intervals of the walk
// outvote it, and the cadence is the walk's.
TEST(Cadence, OneIntervalIsNoCadenceTheMedianOfThreeIs) {
  Cadence c(0.2);
  c.at_step(4.27, 1.0, true);
  c.at_step(4.47, 1.0, true);  // the same step again
  EXPECT_DOUBLE_EQ(c.interval_s(), 0.0);
  c.at_step(5.00, 1.0, true);
  EXPECT_DOUBLE_EQ(c.interval_s(), 0.0);
  c.at_step(5.48, 1.0, true);
  EXPECT_NEAR(c.interval_s(), 0.48, 1e-12);  // median of 0.20, 0.53, 0.48
}

}  // namespace
}  // namespace telltale::fusion
