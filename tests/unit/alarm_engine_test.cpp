#include "telltale/fusion/alarm_engine.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace telltale::fusion {
namespace {

constexpr std::uint64_t kSecond = 1000000000ULL;

AlarmRule heel_band(const std::string& id, double min_deg, double max_deg, double hold_s,
                    double hysteresis_deg, const std::string& scope = "fleet") {
  AlarmRule r;
  r.id = id;
  r.scope = scope;
  r.quantity = AlarmQuantity::kHeel;
  r.min_deg = min_deg;
  r.max_deg = max_deg;
  r.hold_s = hold_s;
  r.hysteresis_deg = hysteresis_deg;
  r.level = AlarmLevel::kAlarm;
  return r;
}

// Feeds heel values at 10 Hz from t0; returns every changed event.
std::vector<AlarmEvent> feed(AlarmEngine& engine, const std::string& boat, std::uint64_t& t,
                             double heel, double seconds) {
  std::vector<AlarmEvent> all;
  for (int k = 0; k < static_cast<int>(seconds * 10); ++k) {
    t += kSecond / 10;
    auto e = engine.evaluate(boat, "ILCA7", t, heel, 0.0);
    all.insert(all.end(), e.begin(), e.end());
  }
  return all;
}

// Given a rule "heel within +-20 held 2 s", when a boat heels 25 deg for 1.5 s, nothing happens;
// when it stays for more than 2 s an alarm is raised once; it clears only below 20 - hysteresis.
TEST(AlarmEngine, HoldAndHysteresis) {
  AlarmEngine engine;
  engine.set_rules({heel_band("too-much", -20, 20, 2.0, 2.0)}, 0);
  std::uint64_t t = 100 * kSecond;
  EXPECT_TRUE(feed(engine, "B1", t, 25.0, 1.5).empty());
  EXPECT_TRUE(feed(engine, "B1", t, 10.0, 1.0).empty());  // back in band: the hold restarts
  auto raised = feed(engine, "B1", t, 25.0, 2.5);
  ASSERT_EQ(raised.size(), 1u);
  EXPECT_EQ(raised[0].phase, AlarmPhase::kRaised);
  EXPECT_EQ(raised[0].level, AlarmLevel::kAlarm);
  EXPECT_DOUBLE_EQ(raised[0].value_deg, 25.0);
  EXPECT_EQ(engine.level_of("B1"), AlarmLevel::kAlarm);
  EXPECT_EQ(engine.level_of("B2"), AlarmLevel::kNormal);
  EXPECT_TRUE(feed(engine, "B1", t, 19.0, 1.0).empty());  // inside, but within the hysteresis
  auto cleared = feed(engine, "B1", t, 17.0, 0.2);
  ASSERT_EQ(cleared.size(), 1u);
  EXPECT_EQ(cleared[0].phase, AlarmPhase::kCleared);
  EXPECT_EQ(cleared[0].id, raised[0].id);
  EXPECT_EQ(engine.level_of("B1"), AlarmLevel::kNormal);
}

TEST(AlarmEngine, ScopesSelectBoats) {
  AlarmEngine engine;
  engine.set_rules({heel_band("g", -5, 5, 0, 0, "group:ILCA7"), heel_band("b", -5, 5, 0, 0, "boat:B9")},
                   0);
  std::uint64_t t = kSecond;
  EXPECT_EQ(engine.evaluate("B1", "ILCA7", t, 10, 0).size(), 1u);   // group rule only
  EXPECT_EQ(engine.evaluate("B2", "470", t, 10, 0).size(), 0u);     // neither
  EXPECT_EQ(engine.evaluate("B9", "470", t, 10, 0).size(), 1u);     // boat rule only
  EXPECT_EQ(engine.evaluate("B9", "ILCA7", t, 10, 0).size(), 1u);   // group rule raises too
}

TEST(AlarmEngine, AcknowledgeSilenceAndRestore) {
  AlarmEngine engine;
  engine.set_rules({heel_band("r", -5, 5, 0, 0)}, 0);
  auto raised = engine.evaluate("B1", "", kSecond, 9, 0);
  ASSERT_EQ(raised.size(), 1u);
  auto acked = engine.acknowledge(raised[0].id, 2 * kSecond);
  ASSERT_TRUE(acked);
  EXPECT_EQ(acked->phase, AlarmPhase::kAcknowledged);
  EXPECT_EQ(acked->acknowledged_ns, 2 * kSecond);
  auto silenced = engine.silence(raised[0].id, 3 * kSecond);
  ASSERT_TRUE(silenced);
  EXPECT_EQ(silenced->phase, AlarmPhase::kSilenced);
  EXPECT_FALSE(engine.acknowledge(999, kSecond));

  // After a restart the active event keeps its phase; it does not raise again and clears later.
  AlarmEngine restarted;
  restarted.restore(engine.rules(), engine.active(), 2);
  EXPECT_EQ(restarted.level_of("B1"), AlarmLevel::kAlarm);
  EXPECT_TRUE(restarted.evaluate("B1", "", 4 * kSecond, 9, 0).empty());
  auto cleared = restarted.evaluate("B1", "", 5 * kSecond, 0, 0);
  ASSERT_EQ(cleared.size(), 1u);
  EXPECT_EQ(cleared[0].id, raised[0].id);
  EXPECT_EQ(cleared[0].acknowledged_ns, 2 * kSecond);
  // New events continue the numbering.
  EXPECT_GT(restarted.evaluate("B1", "", 6 * kSecond, 9, 0).at(0).id, raised[0].id);
}

TEST(AlarmEngine, ChangingARuleClearsItsActiveEvents) {
  AlarmEngine engine;
  engine.set_rules({heel_band("r", -5, 5, 0, 0), heel_band("keep", -8, 8, 0, 0)}, 0);
  ASSERT_EQ(engine.evaluate("B1", "", kSecond, 9, 0).size(), 2u);
  auto cleared = engine.set_rules({heel_band("r", -10, 10, 0, 0), heel_band("keep", -8, 8, 0, 0)},
                                  2 * kSecond);
  ASSERT_EQ(cleared.size(), 1u);
  EXPECT_EQ(cleared[0].rule_id, "r");
  EXPECT_EQ(cleared[0].phase, AlarmPhase::kCleared);
  EXPECT_EQ(engine.active().size(), 1u);
}

TEST(AlarmEngine, NaNNeverRaisesOrClears) {
  AlarmEngine engine;
  engine.set_rules({heel_band("r", -5, 5, 0, 0)}, 0);
  EXPECT_TRUE(engine.evaluate("B1", "", kSecond, std::nan(""), 0).empty());
  ASSERT_EQ(engine.evaluate("B1", "", 2 * kSecond, 9, 0).size(), 1u);
  EXPECT_TRUE(engine.evaluate("B1", "", 3 * kSecond, std::nan(""), 0).empty());
  EXPECT_EQ(engine.level_of("B1"), AlarmLevel::kAlarm);
}

TEST(AlarmRule, Validation) {
  EXPECT_EQ(heel_band("ok", -5, 5, 1, 1).validate(), "");
  EXPECT_NE(heel_band("bad id!", -5, 5, 1, 1).validate(), "");
  EXPECT_NE(heel_band("r", 5, -5, 1, 1).validate(), "");
  EXPECT_NE(heel_band("r", -5, 5, -1, 1).validate(), "");
  EXPECT_NE(heel_band("r", -5, 5, 1, 6).validate(), "");
  EXPECT_NE(heel_band("r", -5, std::nan(""), 1, 1).validate(), "");
  EXPECT_NE(heel_band("r", -5, 5, 1, 1, "group:'; DROP TABLE x").validate(), "");
  AlarmRule normal = heel_band("r", -5, 5, 1, 1);
  normal.level = AlarmLevel::kNormal;
  EXPECT_NE(normal.validate(), "");
}

}  // namespace
}  // namespace telltale::fusion
