// The shore's door: every sample of every topic is checked against
// the wire contract before anything believes it; refusals are counted, never stored, never fatal.
#include "ingest.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "json_views.hpp"

namespace telltale::shore {
namespace {

constexpr std::uint64_t kNow = 1795300000ULL * 1000000000ULL;  // 2026-11-22

msg::BoatAttitude good_attitude(const std::string& id = "b1") {
  msg::BoatAttitude m;
  m.boat_id(id);
  m.seq(1);
  m.t_utc_ns(kNow - 1000);
  m.heel_deg(5.0);
  m.pitch_deg(-2.0);
  m.heading_deg(std::numeric_limits<double>::quiet_NaN());  // no heading source: allowed
  m.quality(1.0f);
  return m;
}

struct Sinks {
  std::vector<AttitudeSample> attitude, backfill;
  std::vector<std::pair<std::string, NodeStatusInfo>> status;
  std::vector<WearableSample> wearable;
  std::vector<FixSample> fixes, fix_backfill;
  std::vector<WindSample> wind;
  IngestSinks sinks() {
    return {[this](const AttitudeSample& s) { attitude.push_back(s); },
            [this](const AttitudeSample& s) { backfill.push_back(s); },
            [this](const std::string& id, const NodeStatusInfo& s) { status.emplace_back(id, s); },
            [this](const WearableSample& w) { wearable.push_back(w); },
            [this](const FixSample& f) { fixes.push_back(f); },
            [this](const FixSample& f) { fix_backfill.push_back(f); },
            [this](const WindSample& w) { wind.push_back(w); }};
  }
};

class IngestTest : public ::testing::Test {
 protected:
  Sinks got;
  Ingest ingest{got.sinks(), [] { return kNow; }};
};

TEST(Utf8, ValidAndInvalid) {
  EXPECT_TRUE(valid_utf8(""));
  EXPECT_TRUE(valid_utf8("plain"));
  EXPECT_TRUE(valid_utf8("h\xC3\xA9"));          // é
  EXPECT_TRUE(valid_utf8("\xF0\x9F\x98\x80"));   // U+1F600
  EXPECT_FALSE(valid_utf8("b\xFF"));             // the byte
  EXPECT_FALSE(valid_utf8("\xC0\xAF"));          // overlong '/'
  EXPECT_FALSE(valid_utf8("\xE0\x80\xAF"));      // overlong, 3 bytes
  EXPECT_FALSE(valid_utf8("\xED\xA0\x80"));      // surrogate
  EXPECT_FALSE(valid_utf8("\xF4\x90\x80\x80"));  // > U+10FFFF
  EXPECT_FALSE(valid_utf8("\xE2\x82"));          // cut short
  EXPECT_FALSE(valid_utf8("\x80"));              // lone continuation
  EXPECT_TRUE(clean_text("GNSS lost, heading from gyro"));
  EXPECT_FALSE(clean_text("a\r\nb"));
  EXPECT_FALSE(clean_text("a\x7F"));
  EXPECT_FALSE(clean_text("a\xC2\x85"));  // NEL, a C1 control
}

TEST(Contract, Ids) {
  EXPECT_TRUE(contract_id("ILCA-7_b"));
  EXPECT_TRUE(contract_id(std::string(32, 'a')));
  for (const std::string& bad :
       {std::string(), std::string("/"), std::string(".."), std::string("."), std::string("a\"b"),
        std::string("a\r\nb"), std::string("\xF0\x9F\x98\x80"), std::string(33, 'a'),
        std::string("b\xFF"), std::string("a b")})
    EXPECT_FALSE(contract_id(bad)) << bad;
}

TEST(Contract, Times) {
  EXPECT_TRUE(contract_time(kNow, kNow));
  EXPECT_TRUE(contract_time(kEarliestSampleNs, kNow));
  EXPECT_TRUE(contract_time(kNow + kMaxAheadNs, kNow));
  EXPECT_FALSE(contract_time(0, kNow));
  EXPECT_FALSE(contract_time(kEarliestSampleNs - 1, kNow));
  EXPECT_FALSE(contract_time(kNow + kMaxAheadNs + 1, kNow));
  EXPECT_FALSE(contract_time(7258118400ULL * 1000000000ULL, kNow));  // 2200
  EXPECT_FALSE(contract_time(1ULL << 63, kNow));
  EXPECT_FALSE(contract_time(UINT64_MAX, kNow));
}

TEST_F(IngestTest, GoodSamplesPass) {
  EXPECT_EQ(ingest.attitude(good_attitude(), false), Reject::kNone);
  EXPECT_EQ(ingest.attitude(good_attitude(), true), Reject::kNone);
  EXPECT_EQ(got.attitude.size(), 1u);
  EXPECT_EQ(got.backfill.size(), 1u);
  EXPECT_EQ(ingest.counters().accepted(Topic::kAttitude), 1u);
  EXPECT_EQ(ingest.counters().rejected_total(), 0u);
}

TEST_F(IngestTest, InvalidUtf8IdIsRefusedOnEveryTopic) {
  EXPECT_EQ(ingest.attitude(good_attitude("b\xFF"), false), Reject::kId);
  EXPECT_EQ(ingest.attitude(good_attitude("b\xFF"), true), Reject::kId);
  msg::NodeStatus st;
  st.node_id("n\xFF");
  st.t_utc_ns(kNow);
  EXPECT_EQ(ingest.status(st), Reject::kId);
  st.node_id("n1");
  st.health_text("bad \xFF\xFE text");
  EXPECT_EQ(ingest.status(st), Reject::kText);
  st.health_text("ok");
  st.group("G\xFF");
  EXPECT_EQ(ingest.status(st), Reject::kText);
  msg::WearableMotion w;
  w.athlete_id("a\xFF");
  w.t_utc_ns(kNow);
  EXPECT_EQ(ingest.wearable(w), Reject::kId);
  EXPECT_TRUE(got.attitude.empty());
  EXPECT_TRUE(got.backfill.empty());
  EXPECT_TRUE(got.status.empty());
  EXPECT_TRUE(got.wearable.empty());
  EXPECT_EQ(ingest.counters().rejected_total(), 6u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kStatus, Reject::kText), 2u);
  const auto j = ingest.counters().to_json();
  EXPECT_EQ(j["rejected"]["backfill"]["id"], 1);
  EXPECT_EQ(j["last_rejected"], "wearable: id");
}

TEST_F(IngestTest, AbsurdTimesAndNonFiniteValuesAreRefused) {
  for (std::uint64_t t : {0ULL, 7258118400ULL * 1000000000ULL, 1ULL << 63, ~0ULL}) {
    auto m = good_attitude();
    m.t_utc_ns(t);
    EXPECT_EQ(ingest.attitude(m, true), Reject::kTime) << t;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto heel = good_attitude();
  heel.heel_deg(nan);
  EXPECT_EQ(ingest.attitude(heel, true), Reject::kValue);
  auto pitch = good_attitude();
  pitch.pitch_deg(inf);
  EXPECT_EQ(ingest.attitude(pitch, false), Reject::kValue);
  auto heading = good_attitude();
  heading.heading_deg(inf);
  EXPECT_EQ(ingest.attitude(heading, false), Reject::kValue);
  auto rate = good_attitude();
  rate.yaw_rate_deg_s(nan);
  EXPECT_EQ(ingest.attitude(rate, false), Reject::kValue);
  auto big = good_attitude();
  big.heel_deg(1e300);
  EXPECT_EQ(ingest.attitude(big, false), Reject::kValue);
  EXPECT_TRUE(got.attitude.empty());
  EXPECT_TRUE(got.backfill.empty());
  EXPECT_EQ(ingest.counters().rejected(Topic::kBackfill, Reject::kTime), 4u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kBackfill, Reject::kValue), 1u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kAttitude, Reject::kValue), 4u);
}

/// A BoatAttitude payload by hand, with any id (the generated type cannot hold more than 32).
eprosima::fastrtps::rtps::SerializedPayload_t payload_with_id(const std::string& id) {
  msg::BoatAttitude m = good_attitude();
  eprosima::fastrtps::rtps::SerializedPayload_t p(4096 + static_cast<std::uint32_t>(id.size()));
  eprosima::fastcdr::FastBuffer buf(reinterpret_cast<char*>(p.data), p.max_size);
  eprosima::fastcdr::Cdr ser(buf, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                             eprosima::fastcdr::Cdr::DDS_CDR);
  ser.serialize_encapsulation();
  ser << id;
  ser << m.seq() << m.t_utc_ns() << m.heel_deg() << m.pitch_deg() << m.heading_deg()
      << m.heel_rate_deg_s() << m.pitch_rate_deg_s() << m.yaw_rate_deg_s() << m.accel_weight()
      << m.quality();
  m.leds().serialize(ser);
  ser << m.boot_id();
  p.length = static_cast<std::uint32_t>(ser.getSerializedDataLength());
  return p;
}

// Finding 11: a 10 000-character id used to arrive truncated to 32 (two ids merged); a NUL inside
// cut it short the same way. The strict type turns both into an empty id, which the door refuses.
TEST_F(IngestTest, OverlongOrNulIdsAreNotTruncatedIntoValidOnes) {
  StrictBoatAttitudeType type;
  msg::BoatAttitude m;
  auto ok = payload_with_id("b1");
  ASSERT_TRUE(type.deserialize(&ok, &m));
  EXPECT_EQ(m.boat_id().to_string(), "b1");
  EXPECT_EQ(ingest.attitude(m, false), Reject::kNone);

  auto longer = payload_with_id(std::string(10000, 'a'));
  ASSERT_TRUE(type.deserialize(&longer, &m));
  EXPECT_EQ(ingest.attitude(m, false), Reject::kId);
  auto just_over = payload_with_id(std::string(33, 'a'));
  ASSERT_TRUE(type.deserialize(&just_over, &m));
  EXPECT_EQ(ingest.attitude(m, false), Reject::kId);
  auto nul = payload_with_id("b1xb2");  // Fast CDR writes strings up to a NUL: patch one in
  nul.data[8 + 2] = 0;                  // 4 bytes encapsulation, 4 bytes length, then chars
  ASSERT_TRUE(type.deserialize(&nul, &m));
  EXPECT_EQ(ingest.attitude(m, false), Reject::kId);
  EXPECT_EQ(got.attitude.size(), 1u);

  // The generated type alone is what let them through.
  msg::BoatAttitudePubSubType plain;
  auto again = payload_with_id(std::string(10000, 'a'));
  ASSERT_TRUE(plain.deserialize(&again, &m));
  EXPECT_EQ(m.boat_id().to_string(), std::string(32, 'a'));

  // Garbage is not a sample and throws nothing.
  eprosima::fastrtps::rtps::SerializedPayload_t junk(16);
  junk.length = 16;
  for (std::uint32_t i = 0; i < 16; ++i) junk.data[i] = 0xFF;
  EXPECT_NO_THROW((void)type.deserialize(&junk, &m));
}

// Finding 1, the output half: a string that is not UTF-8 (stored before the door existed) must
// not make a response throw.
TEST(JsonText, InvalidUtf8IsReplacedNotThrown) {
  BoatView v;
  v.last.boat_id = "b\xFF";
  v.status = NodeStatusInfo{};
  v.status->health_text = "\xFE\xFF";
  std::string text;
  ASSERT_NO_THROW(text = boat_json(v));
  EXPECT_NE(text.find("b\xEF\xBF\xBD"), std::string::npos);
  // Still one valid JSON object, the replaced health text inside.
  const auto j = nlohmann::json::parse(text);
  EXPECT_EQ(j.at("status").at("health_text"), "\xEF\xBF\xBD\xEF\xBF\xBD");
  SessionInfo s;
  s.boat_id = "x\xFF";
  EXPECT_NO_THROW((void)to_json_text(session_object(s)));
}

}  // namespace
}  // namespace telltale::shore

namespace telltale::shore {
namespace {

msg::BoatFix good_fix() {
  msg::BoatFix m;
  m.boat_id("b1");
  m.seq(1);
  m.t_utc_ns(kNow - 1000000000ULL);
  m.gnss_utc_ns(kNow - 1000000000ULL);
  m.lat_deg(54.344);
  m.lon_deg(10.19);
  m.sog_m_s(3.0);
  m.cog_deg(42.0);
  m.fix(msg::FIX_KIND_3D);
  m.satellites(11);
  m.hdop(0.8f);
  return m;
}

// Given fixes off the contract (a position without a fix, a fix without a position, values
// out of range or NaN where a number is due, an unknown fix kind), the door refuses and counts
// each; a good fix and a no-fix epoch pass.
TEST_F(IngestTest, FixesOffTheContractAreRefusedAndCounted) {
  EXPECT_EQ(ingest.fix(good_fix()), Reject::kNone);
  auto none = good_fix();
  none.fix(msg::FIX_KIND_NONE);
  none.lat_deg(std::nan(""));
  none.lon_deg(std::nan(""));
  none.sog_m_s(std::nan(""));
  none.cog_deg(std::nan(""));
  EXPECT_EQ(ingest.fix(none), Reject::kNone);
  ASSERT_EQ(got.fixes.size(), 2u);
  EXPECT_EQ(got.fixes[0].fix, "3d");
  EXPECT_EQ(got.fixes[1].fix, "none");

  std::vector<msg::BoatFix> bad;
  auto m = good_fix();
  m.lat_deg(91.0);
  bad.push_back(m);
  m = good_fix();
  m.lon_deg(std::nan(""));
  bad.push_back(m);
  m = good_fix();
  m.lon_deg(-180.5);
  bad.push_back(m);
  m = good_fix();
  m.sog_m_s(-1.0);
  bad.push_back(m);
  m = good_fix();
  m.sog_m_s(std::numeric_limits<double>::infinity());
  bad.push_back(m);
  m = good_fix();
  m.cog_deg(400.0);
  bad.push_back(m);
  m = good_fix();
  m.hdop(-1.0f);
  bad.push_back(m);
  m = good_fix();
  m.fix(static_cast<msg::FixKind>(9));
  bad.push_back(m);
  m = good_fix();
  m.fix(msg::FIX_KIND_NONE);
  bad.push_back(m);  // none, yet a position
  for (const auto& b : bad) EXPECT_EQ(ingest.fix(b), Reject::kValue) << b.lat_deg();
  m = good_fix();
  m.boat_id("bad id");
  EXPECT_EQ(ingest.fix(m), Reject::kId);
  m = good_fix();
  m.t_utc_ns(1);
  EXPECT_EQ(ingest.fix(m), Reject::kTime);
  m = good_fix();
  m.gnss_utc_ns(5);
  EXPECT_EQ(ingest.fix(m), Reject::kTime);
  EXPECT_EQ(got.fixes.size(), 2u);
  EXPECT_EQ(ingest.counters().accepted(Topic::kFix), 2u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kFix, Reject::kValue), bad.size());
  EXPECT_EQ(ingest.counters().rejected(Topic::kFix, Reject::kId), 1u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kFix, Reject::kTime), 2u);
}

// A fix resent from a boat's log passes the same door, into its own sink (the recording only) and
// its own counters; off the contract it is refused there, as a live one.
TEST_F(IngestTest, WindReadingsOffTheContractAreRefusedAndCounted) {
  msg::BoatWind m;
  m.boat_id("ILCA-1");
  m.seq(3);
  m.t_utc_ns(kNow - 1'000'000'000ULL);
  m.from_deg(212.5);
  m.speed_m_s(std::nan(""));  // the instrument gave no speed: allowed
  m.source("mwv_apparent");
  m.boot_id(77);
  EXPECT_EQ(ingest.wind(m), Reject::kNone);
  ASSERT_EQ(got.wind.size(), 1u);
  EXPECT_EQ(got.wind[0].boat_id, "ILCA-1");
  EXPECT_EQ(got.wind[0].from_deg, 212.5);
  EXPECT_EQ(got.wind[0].source, "mwv_apparent");
  EXPECT_EQ(got.wind[0].boot_id, 77u);
  auto bad = m;
  bad.from_deg(std::nan(""));
  EXPECT_EQ(ingest.wind(bad), Reject::kValue);
  bad = m;
  bad.from_deg(361.0);
  EXPECT_EQ(ingest.wind(bad), Reject::kValue);
  bad = m;
  bad.speed_m_s(-2.0);
  EXPECT_EQ(ingest.wind(bad), Reject::kValue);
  bad = m;
  bad.source("<script>");
  EXPECT_EQ(ingest.wind(bad), Reject::kText);
  bad = m;
  bad.boat_id("");
  EXPECT_EQ(ingest.wind(bad), Reject::kId);
  bad = m;
  bad.t_utc_ns(0);
  EXPECT_EQ(ingest.wind(bad), Reject::kTime);
  EXPECT_EQ(got.wind.size(), 1u);
  EXPECT_EQ(ingest.counters().accepted(Topic::kWind), 1u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kWind, Reject::kValue), 3u);
  EXPECT_TRUE(ingest.counters().to_json()["rejected"].contains("wind"));
}

TEST_F(IngestTest, BackfilledFixesPassTheSameDoorIntoTheirOwnSink) {
  EXPECT_EQ(ingest.fix(good_fix(), true), Reject::kNone);
  auto m = good_fix();
  m.lat_deg(91.0);
  EXPECT_EQ(ingest.fix(m, true), Reject::kValue);
  EXPECT_TRUE(got.fixes.empty());
  ASSERT_EQ(got.fix_backfill.size(), 1u);
  EXPECT_EQ(got.fix_backfill[0].fix, "3d");
  EXPECT_EQ(ingest.counters().accepted(Topic::kFixBackfill), 1u);
  EXPECT_EQ(ingest.counters().rejected(Topic::kFixBackfill, Reject::kValue), 1u);
  EXPECT_EQ(ingest.counters().accepted(Topic::kFix), 0u);
  EXPECT_TRUE(ingest.counters().to_json()["rejected"].contains("fix_backfill"));
}

}  // namespace
}  // namespace telltale::shore
