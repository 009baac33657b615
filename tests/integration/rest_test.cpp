// The REST API over real HTTP against a real shore fed by a real boat over DDS: hostile input of
// every kind gets the right 4xx and changes nothing; alarms, sessions, exports and acks work and
// survive a restart.
#include <signal.h>

#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

constexpr const char* kAnalyst = "analyst-token";
constexpr const char* kAthlete = "athlete-token";

class RestTest : public ShoreFixture {
 protected:
  std::vector<std::string> shore_flags() const override {
    return {"--analyst-token", kAnalyst, "--athlete-token", std::string("rb1:") + kAthlete};
  }

  /// A boat sails for a few seconds under a rule it breaks, then stops: a recorded session with
  /// an alarm event to work on.
  void record_session() {
    auto c = client();
    auto put = c.Put("/api/v1/alarms/rules", bearer(),
                     R"([{"id":"flat","quantity":"heel","min_deg":-2,"max_deg":2,"hold_s":0.2,
                          "hysteresis_deg":0.5,"level":"alarm"}])",
                     "application/json");
    ASSERT_TRUE(put);
    ASSERT_EQ(put->status, 200) << put->body;
    Process& boat = start_boat("rb1", {"--group", "ILCA7"});
    ASSERT_TRUE(eventually([&] { return get_json("/api/v1/alarms/events").size() >= 1; }, 15s))
        << shore_->output();
    std::this_thread::sleep_for(3s);
    ASSERT_EQ(boat.stop(SIGINT), 0);
    std::this_thread::sleep_for(600ms);  // > the 250 ms durability window
  }
};

struct Case {
  std::string method;
  std::string path;
  std::string body;
  std::string content_type;
  std::string token;
  int status;
};

TEST_F(RestTest, HostileInputGetsTheRight4xxAndChangesNothing) {
  record_session();
  const json rules_before = get_json("/api/v1/alarms/rules");
  const json events_before = get_json("/api/v1/alarms/events");
  const json sessions_before = get_json("/api/v1/sessions");
  ASSERT_EQ(sessions_before.size(), 1u);
  const std::string sid = std::to_string(sessions_before[0]["id"].get<int>());
  const std::string coach = kCoachToken;
  const std::string rule = R"({"id":"r","quantity":"heel","min_deg":-5,"max_deg":5})";

  const std::vector<Case> cases = {
      // authentication and roles
      {"GET", "/api/v1/boats", "", "", "", 401},
      {"GET", "/api/v1/boats", "", "", "wrong-token", 401},
      {"GET", "/api/v1/boats?token=" + coach, "", "", "", 401},
      {"PUT", "/api/v1/alarms/rules", "[" + rule + "]", "application/json", kAnalyst, 403},
      {"POST", "/api/v1/alarms/events/1/ack", "", "text/plain", kAnalyst, 403},
      {"GET", "/api/v1/boats/other/attitude", "", "", kAthlete, 403},
      {"GET", "/api/v1/sessions?boat=other", "", "", kAthlete, 403},
      // unknown ids and malicious ids
      {"GET", "/api/v1/boats/nope", "", "", coach, 404},
      {"GET", "/api/v1/boats/nope/attitude", "", "", coach, 404},
      {"GET", "/api/v1/boats/rb1'%20OR%20'1'='1/attitude", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1%3BDROP%20TABLE%20attitude/attitude", "", "", coach, 400},
      {"GET", "/api/v1/sessions/999999", "", "", coach, 404},
      {"GET", "/api/v1/sessions/abc", "", "", coach, 400},
      {"GET", "/api/v1/sessions/-1", "", "", coach, 400},
      {"GET", "/api/v1/sessions/1%20OR%201=1", "", "", coach, 400},
      {"GET", "/api/v1/sessions?boat=x'%20OR%20'1'='1", "", "", coach, 400},
      {"GET", "/api/v1/no/such/route", "", "", coach, 404},
      // ranges, numbers, formats
      {"GET", "/api/v1/boats/rb1/attitude?from=200&to=100", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=nan", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=NaN&to=inf", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=1e309", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=-5", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?to=2026-02-30T00:00:00Z", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=0&to=99999999999999999999", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?max_points=0", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?max_points=abc", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?max_points=1000000000", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?format=xml", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?format=csv&max_points=10", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?colour=red", "", "", coach, 400},
      {"GET", "/api/v1/boats/rb1/attitude?from=1&from=2", "", "", coach, 400},
      {"GET", "/api/v1/sessions/" + sid + "/export", "", "", coach, 400},
      {"GET", "/api/v1/sessions/" + sid + "/export?format=xlsx", "", "", coach, 400},
      {"GET", "/api/v1/alarms/events?active=maybe", "", "", coach, 400},
      {"GET", "/api/v1/alarms/events?limit=0", "", "", coach, 400},
      // bodies
      {"PUT", "/api/v1/alarms/rules", "[{\"id\":", "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", rule, "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", "[" + rule + "]", "text/plain", coach, 415},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r","quantity":"heel","min_deg":NaN}])",
       "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r","quantity":"heel","min_deg":"5"}])",
       "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r","quantity":"heel","min_deg":5,"max_deg":-5}])",
       "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r","quantity":"yaw"}])", "application/json",
       coach, 400},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r'; DROP TABLE alarm_rules; --","quantity":"heel"}])",
       "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", R"([{"id":"r","quantity":"heel","sql":"x"}])",
       "application/json", coach, 400},
      {"PUT", "/api/v1/alarms/rules", "[" + rule + "," + rule + "]", "application/json", coach,
       400},
      {"PUT", "/api/v1/alarms/rules", std::string(20 * 1024 * 1024, '['), "application/json",
       coach, 413},
      {"POST", "/api/v1/alarms/events/abc/ack", "", "text/plain", coach, 400},
      {"POST", "/api/v1/alarms/events/999999/ack", "", "text/plain", coach, 404},
  };

  auto c = client();
  for (const Case& k : cases) {
    SCOPED_TRACE(k.method + " " + k.path.substr(0, 120));
    httplib::Headers h;
    if (!k.token.empty()) h = bearer(k.token);
    httplib::Result res = k.method == "GET"    ? c.Get(k.path, h)
                          : k.method == "PUT"  ? c.Put(k.path, h, k.body, k.content_type)
                                               : c.Post(k.path, h, k.body, k.content_type);
    ASSERT_TRUE(res) << "no response";
    EXPECT_EQ(res->status, k.status) << res->body;
    const json body = json::parse(res->body, nullptr, false);
    EXPECT_TRUE(body.is_object() && body.contains("error") && body["error"].is_string())
        << res->body;
  }
  // Nothing changed, and the shore is still healthy.
  EXPECT_EQ(get_json("/api/v1/alarms/rules"), rules_before);
  EXPECT_EQ(get_json("/api/v1/alarms/events"), events_before);
  EXPECT_EQ(get_json("/api/v1/sessions"), sessions_before);
  EXPECT_EQ(get_json("/healthz")["status"], "ok");
  EXPECT_TRUE(shore_->running());
}

TEST_F(RestTest, SessionsAttitudeAndStreamedExportAgree) {
  record_session();
  const json sessions = get_json("/api/v1/sessions?boat=rb1");
  ASSERT_EQ(sessions.size(), 1u);
  const json& s = sessions[0];
  const int samples = s["samples"];
  EXPECT_GT(samples, 50);
  const std::string sid = std::to_string(s["id"].get<int>());

  auto c = client();
  auto csv = c.Get("/api/v1/sessions/" + sid + "/export?format=csv", bearer(kAnalyst));
  ASSERT_TRUE(csv);
  ASSERT_EQ(csv->status, 200);
  EXPECT_NE(csv->get_header_value("Content-Disposition").find("attachment"), std::string::npos);
  int lines = 0;
  for (char ch : csv->body) lines += ch == '\n';
  EXPECT_EQ(lines, samples + 1);  // header + one row per stored sample
  EXPECT_EQ(csv->body.rfind("time_utc,t_s,seq,heel_deg,pitch_deg", 0), 0u);

  auto js = c.Get("/api/v1/sessions/" + sid + "/export?format=json", bearer());
  ASSERT_TRUE(js);
  const json doc = json::parse(js->body);
  EXPECT_EQ(doc["samples"].size(), static_cast<std::size_t>(samples));
  EXPECT_EQ(doc["session"]["id"], s["id"]);

  const json full = get_json("/api/v1/sessions/" + sid + "/attitude");
  EXPECT_EQ(full["count"], samples);
  EXPECT_FALSE(full["downsampled"].get<bool>());
  EXPECT_EQ(full["session_id"], s["id"]);
  // The chart's columns are written as text directly: each number reads back to the stored
  // value exactly, and a missing one is null, as in the export.
  ASSERT_EQ(full["heel_deg"].size(), doc["samples"].size());
  for (std::size_t i = 0; i < doc["samples"].size(); ++i) {
    const json& row = doc["samples"][i];
    EXPECT_EQ(full["heel_deg"][i], row["heel_deg"]) << i;
    EXPECT_EQ(full["pitch_deg"][i], row["pitch_deg"]) << i;
    EXPECT_EQ(full["heading_deg"][i], row["heading_deg"]) << i;
  }
  const json small = get_json("/api/v1/sessions/" + sid + "/attitude?max_points=40");
  EXPECT_TRUE(small["downsampled"].get<bool>());
  EXPECT_LE(small["t_s"].size(), 40u);
  EXPECT_EQ(small["count"], samples);  // from the chart tiers: the session is whole buckets
  // Peaks survive downsampling.
  const auto max_of = [](const json& a) {
    double m = -1e9;
    for (const auto& v : a) m = std::max(m, v.get<double>());
    return m;
  };
  EXPECT_DOUBLE_EQ(max_of(small["heel_deg"]), max_of(full["heel_deg"]));

  const json detail = get_json("/api/v1/sessions/" + sid);
  double banded = 0;
  for (const auto& b : detail["heel_bands"]) banded += b["seconds"].get<double>();
  EXPECT_NEAR(banded, s["duration_s"].get<double>(), 0.2);
  EXPECT_GE(detail["alarm_events"].size(), 1u);

  // An athlete sees their own boat, and only it.
  auto mine = c.Get("/api/v1/sessions", bearer(kAthlete));
  ASSERT_TRUE(mine);
  EXPECT_EQ(json::parse(mine->body).size(), 1u);
}

// Acknowledged alarms and the rules survive a restart of the shore on the same database.
TEST_F(RestTest, AlarmAcksAndRulesSurviveRestart) {
  record_session();
  const json events = get_json("/api/v1/alarms/events?active=true");
  ASSERT_GE(events.size(), 1u);
  const std::string id = std::to_string(events[0]["id"].get<int>());
  auto c = client();
  auto ack = c.Post("/api/v1/alarms/events/" + id + "/ack", bearer(), "", "text/plain");
  ASSERT_TRUE(ack);
  ASSERT_EQ(ack->status, 200);
  EXPECT_EQ(json::parse(ack->body)["phase"], "acknowledged");
  const json rules = get_json("/api/v1/alarms/rules");

  ASSERT_EQ(shore_->stop(SIGKILL), 128 + SIGKILL);  // no clean shutdown
  start_shore();
  EXPECT_EQ(get_json("/api/v1/alarms/rules"), rules);
  const json after = get_json("/api/v1/alarms/events?active=true");
  ASSERT_GE(after.size(), 1u);
  bool found = false;
  for (const auto& e : after) {
    if (std::to_string(e["id"].get<int>()) != id) continue;
    found = true;
    EXPECT_EQ(e["phase"], "acknowledged");
    EXPECT_TRUE(e["acknowledged_at"].is_string());
  }
  EXPECT_TRUE(found);
  const auto boats = boats_by_id();
  ASSERT_TRUE(boats.count("rb1"));
  EXPECT_EQ(boats.at("rb1")["alarm_state"], "alarm");
}

}  // namespace
}  // namespace telltale::testing
