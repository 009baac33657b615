// Issue 25: a hostile (or broken) DDS publisher on the shore's domain, built on our own generated
// types. Nothing it sends may kill the shore, reach the recording or break the API; every refusal
// is counted in /healthz.
#include <signal.h>
#include <sqlite3.h>

#include <cmath>
#include <fstream>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <limits>

#include "dds_participant.hpp"
#include "shore_fixture.hpp"
#include "telltalePubSubTypes.h"

namespace telltale::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// A publisher of every topic the shore reads, writing whatever it is given.
class HostilePublisher {
 public:
  explicit HostilePublisher(int domain) {
    dds::DdsOptions o;
    o.domain = domain;
    participant_ = std::make_unique<dds::Participant>(o, "hostile");
    auto& p = *participant_;
    attitude_ = p.writer(
        p.topic(dds::kTopicBoatAttitude, fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
        "attitude_writer");
    backfill_ = p.writer(
        p.topic(dds::kTopicBoatBackfill, fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
        "backfill_writer");
    status_ =
        p.writer(p.topic(dds::kTopicNodeStatus, fdds::TypeSupport(new msg::NodeStatusPubSubType())),
                 "status_writer");
    wearable_ = p.writer(
        p.topic(dds::kTopicWearableMotion, fdds::TypeSupport(new msg::WearableMotionPubSubType())),
        "wearable_writer");
  }

  /// True once the shore's reader of every topic is matched.
  bool wait_matched(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      bool all = true;
      for (auto* w : {attitude_, backfill_, status_, wearable_}) {
        fdds::PublicationMatchedStatus st;
        w->get_publication_matched_status(st);
        all = all && st.current_count > 0;
      }
      if (all) return true;
      std::this_thread::sleep_for(50ms);
    }
    return false;
  }

  static msg::BoatAttitude attitude(const std::string& id, std::uint64_t seq, std::uint64_t t) {
    msg::BoatAttitude m;
    m.boat_id(id);
    m.seq(seq);
    m.t_utc_ns(t);
    m.heel_deg(3.0);
    m.pitch_deg(-1.0);
    m.heading_deg(std::numeric_limits<double>::quiet_NaN());
    m.quality(1.0f);
    m.accel_weight(1.0f);
    m.boot_id(77);
    return m;
  }
  /// Best effort topics: each sample three times, spaced, so one lost datagram changes nothing.
  void live(msg::BoatAttitude m) {
    for (int i = 0; i < 3; ++i) {
      attitude_->write(&m);
      std::this_thread::sleep_for(5ms);
    }
  }
  void backfill(msg::BoatAttitude m) { backfill_->write(&m); }
  void status(const std::string& node, const std::string& text, std::uint64_t t) {
    msg::NodeStatus m;
    m.node_id(node);
    m.kind(msg::NODE_KIND_BOAT);
    m.software_version("hostile");
    m.t_utc_ns(t);
    m.health_text(text);
    status_->write(&m);
  }
  void wearable(const std::string& athlete, std::uint64_t t) {
    msg::WearableMotion m;
    m.athlete_id(athlete);
    m.seq(1);
    m.t_utc_ns(t);
    for (int i = 0; i < 3; ++i) {
      wearable_->write(&m);
      std::this_thread::sleep_for(5ms);
    }
  }

 private:
  std::unique_ptr<dds::Participant> participant_;
  fdds::DataWriter* attitude_ = nullptr;
  fdds::DataWriter* backfill_ = nullptr;
  fdds::DataWriter* status_ = nullptr;
  fdds::DataWriter* wearable_ = nullptr;
};

class HostileSampleTest : public ShoreFixture {
 protected:
  json healthz() const {
    auto c = client();
    auto res = c.Get("/healthz");
    if (!res || res->status != 200) return nullptr;
    return json::parse(res->body, nullptr, false);
  }
  std::uint64_t rejected(const char* topic, const char* reason) const {
    const json h = healthz();
    if (!h.is_object() || !h.contains("ingest")) return 0;
    return h["ingest"]["rejected"][topic][reason].get<std::uint64_t>();
  }
};

// Finding 1: one byte 0xFF in a boat id killed the shore (nlohmann type_error 316 in the live
// worker); sent on the backfill topic it was stored and /api/v1/sessions answered 500 for good.
TEST_F(HostileSampleTest, InvalidUtf8NeitherKillsTheShoreNorPoisonsTheApi) {
  HostilePublisher pub(domain_);
  ASSERT_TRUE(pub.wait_matched(10s));
  const std::uint64_t t0 = now_ns() - 5'000'000'000ULL;
  // A good boat first, so a bad status text has a boat to land on.
  for (std::uint64_t i = 1; i <= 3; ++i) pub.live(HostilePublisher::attitude("good1", i, t0 + i));
  ASSERT_TRUE(eventually([&] { return boats_by_id().count("good1") == 1; }, 10s))
      << shore_->output();
  pub.live(HostilePublisher::attitude("b\xFF", 1, t0 + 10));
  for (std::uint64_t i = 1; i <= 3; ++i)
    pub.backfill(HostilePublisher::attitude("b\xFF", i, t0 + 20 + i));
  pub.status("good1", "sensor \xFF\xFE broken", t0);
  pub.status("n\xFF", "ok", t0);
  pub.wearable("a\xFF", t0);
  std::this_thread::sleep_for(1500ms);  // > the 250 ms commit window

  ASSERT_TRUE(shore_->running()) << "the shore died: " << shore_->output();
  auto c = client();
  for (const char* path : {"/api/v1/sessions", "/api/v1/boats", "/api/v1/athletes"}) {
    auto res = c.Get(path, bearer());
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 200) << path << ": " << res->body;
  }
  const json sessions = get_json("/api/v1/sessions");
  ASSERT_TRUE(sessions.is_array());
  for (const auto& s : sessions) EXPECT_EQ(s["boat_id"], "good1");
  EXPECT_GE(rejected("attitude", "id"), 1u);
  EXPECT_GE(rejected("backfill", "id"), 3u);
  EXPECT_GE(rejected("status", "id"), 1u);
  EXPECT_GE(rejected("status", "text"), 1u);
  EXPECT_GE(rejected("wearable", "id"), 1u);
  EXPECT_GE(healthz()["samples_rejected"].get<std::uint64_t>(), 7u);

  // And after a restart (the poisoned recording used to fail every start).
  ASSERT_EQ(shore_->stop(SIGTERM), 0);
  start_shore();
  auto res = client().Get("/api/v1/sessions", bearer());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200) << res->body;
}

// Finding 1, the stored half: a database written before the door existed may hold such bytes;
// every response that shows them must still be JSON (U+FFFD in their place), never a 500.
TEST_F(HostileSampleTest, StoredInvalidUtf8StillAnswers) {
  ASSERT_EQ(shore_->stop(SIGTERM), 0);
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(db_path().c_str(), &db), SQLITE_OK);
    const std::string t = std::to_string(now_ns() - 60'000'000'000ULL);
    const std::string sql =
        "INSERT INTO sessions (boat_id, start_ns, end_ns, samples) VALUES ('x\xFF', " + t + ", " +
        t +
        ", 1); INSERT INTO attitude (boat_id, t_utc_ns, seq, heel_deg, pitch_deg) VALUES "
        "('x\xFF', " +
        t + ", 1, 1.0, 2.0);";
    char* err = nullptr;
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK) << err;
    sqlite3_close(db);
  }
  start_shore();
  auto c = client();
  auto res = c.Get("/api/v1/sessions", bearer());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const json sessions = json::parse(res->body);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0]["boat_id"], "x\xEF\xBF\xBD");
  const std::string sid = std::to_string(sessions[0]["id"].get<int>());
  for (const std::string& path :
       {"/api/v1/sessions/" + sid, "/api/v1/sessions/" + sid + "/attitude",
        "/api/v1/sessions/" + sid + "/export?format=json",
        "/api/v1/sessions/" + sid + "/export?format=csv"}) {
    auto r = c.Get(path, bearer());
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 200) << path << ": " << r->body;
    const std::string disposition = r->get_header_value("Content-Disposition");
    EXPECT_EQ(disposition.find('\xFF'), std::string::npos) << disposition;
  }
}

// Findings 11 and 12: ids outside the contract, absurd times and NaN angles are refused at the
// door and counted; only the good boat's samples are stored.
TEST_F(HostileSampleTest, IdsTimesAndNaNOffContractAreRefusedAndCounted) {
  HostilePublisher pub(domain_);
  ASSERT_TRUE(pub.wait_matched(10s));
  const std::uint64_t now = now_ns();
  const std::vector<std::string> bad_ids = {
      "", "/", "..", ".", "a\"b", "a\r\nb", "a b", "\xF0\x9F\x98\x80", "a/../b", "<script>"};
  std::uint64_t seq = 0;
  // Live topic for the ids: the backfill writer's profile holds one instance (its own boat).
  for (const auto& id : bad_ids) pub.live(HostilePublisher::attitude(id, ++seq, now - 1000));
  const std::vector<std::uint64_t> bad_times = {0,
                                                1,
                                                946684799ULL * 1000000000ULL,   // 1999-12-31
                                                7258118400ULL * 1000000000ULL,  // 2200-01-01
                                                now + 2 * 86400ULL * 1000000000ULL,
                                                1ULL << 63,
                                                UINT64_MAX};
  for (auto t : bad_times) pub.backfill(HostilePublisher::attitude("tb", ++seq, t));
  auto nan_heel = HostilePublisher::attitude("tb", ++seq, now - 2000);
  nan_heel.heel_deg(std::numeric_limits<double>::quiet_NaN());
  pub.backfill(nan_heel);
  auto inf_pitch = HostilePublisher::attitude("tb", ++seq, now - 3000);
  inf_pitch.pitch_deg(std::numeric_limits<double>::infinity());
  pub.backfill(inf_pitch);
  pub.backfill(HostilePublisher::attitude("tb", ++seq, now - 4000));  // the one good sample

  ASSERT_TRUE(eventually(
      [&] {
        const json s = get_json("/api/v1/sessions");
        return s.is_array() && !s.empty();
      },
      10s))
      << shore_->output();
  std::this_thread::sleep_for(1s);
  const json sessions = get_json("/api/v1/sessions");
  ASSERT_EQ(sessions.size(), 1u) << sessions.dump(1);
  EXPECT_EQ(sessions[0]["boat_id"], "tb");
  EXPECT_EQ(sessions[0]["samples"], 1);
  EXPECT_NEAR(sessions[0]["start_t_s"].get<double>(), static_cast<double>(now) * 1e-9, 60.0);
  EXPECT_GE(rejected("attitude", "id"), bad_ids.size());  // each sent three times
  EXPECT_EQ(rejected("backfill", "time"), bad_times.size());
  EXPECT_EQ(rejected("backfill", "value"), 2u);
  ASSERT_TRUE(shore_->running());
}

// Finding 8, the DDS half: Fast DDS frees an instance (one per id) only once no writer holds it, so
// a publisher that invented as many ids as a reader's table holds kept every new boat out for as
// long as it lived (the door runs after Fast DDS has taken the id in). The shore now replaces a
// reader whose table filled. Here the table holds 8 ids, the publisher takes them all and goes
// quiet, then a real boat starts: it must appear, and the refusals are counted in /healthz.
class FullReaderTest : public HostileSampleTest {
 protected:
  std::vector<std::string> shore_flags() const override {
    std::ifstream in(dds::resolve_profiles_file(""));
    std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string reader = "<data_reader profile_name=\"attitude_reader\">";
    const auto at = xml.find(reader);
    const auto limit = xml.find("<max_instances>4096</max_instances>", at);
    EXPECT_NE(limit, std::string::npos) << "the attitude reader's instance limit moved";
    if (limit != std::string::npos)
      xml.replace(limit, std::string("<max_instances>4096</max_instances>").size(),
                  "<max_instances>8</max_instances>");
    const std::string path = dir_ + "/small_reader_profiles.xml";
    std::ofstream(path) << xml;
    return {"--dds-profiles", path};
  }
};

TEST_F(FullReaderTest, IdsInventedToFillTheReaderDoNotLockANewBoatOut) {
  HostilePublisher pub(domain_);
  ASSERT_TRUE(pub.wait_matched(10s));
  const std::uint64_t t0 = now_ns() - 5'000'000'000ULL;
  for (std::uint64_t id = 0; id < 12; ++id)
    pub.live(HostilePublisher::attitude("inv" + std::to_string(id), 1, t0 + id));
  ASSERT_TRUE(eventually([&] { return rejected("attitude", "reader_full") > 0; }, 10s))
      << healthz().dump(1);
  start_boat("late1");
  EXPECT_TRUE(eventually([&] { return boats_by_id().count("late1") == 1; }, 20s))
      << shore_->output();
  ASSERT_TRUE(shore_->running());
}

}  // namespace
}  // namespace telltale::testing
