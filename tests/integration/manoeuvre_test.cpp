// Manoeuvres end to end: a simulated boat sails its race course (seed 10 tacks ~28 s
// after the start) into a real shore; the session's /manoeuvres lists the tack, in JSON and CSV,
// and the live stream pushes it, found and then final, measured as the REST endpoint measures it.
// The boat's simulated IMU is the same boat (the race scenario): its heel flips at the tack.
#include <string>
#include <vector>

#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

class ManoeuvreTest : public ShoreFixture {};

TEST_F(ManoeuvreTest, ASimBoatsSessionListsItsTack) {
  start_boat("tack1", {"--seed", "10"});
  json got;
  ASSERT_TRUE(eventually(
      [&] {
        const auto s = get_json("/api/v1/sessions?boat=tack1");
        if (!s.is_array() || s.empty()) return false;
        got = get_json("/api/v1/sessions/" + std::to_string(s[0]["id"].get<int>()) +
                       "/manoeuvres?wind_from_deg=255");
        // A tack whose 20 s after are in (its heel check is made then).
        for (const auto& m : got["manoeuvres"])
          if (m["kind"] == "tack" && !m["heel_flip_agrees"].is_null()) return true;
        return false;
      },
      80s))
      << got.dump();
  const auto& m = got["manoeuvres"][0];
  EXPECT_EQ(m["kind"], "tack");
  EXPECT_NEAR(m["turn_deg"].get<double>(), 84.0, 10.0);
  EXPECT_TRUE(m["t_utc"].is_string());
  EXPECT_TRUE(m["distance_lost_m"].is_number());
  EXPECT_TRUE(m.contains("heel_peak_deg"));
  EXPECT_EQ(got["wind"]["given"], true);
  EXPECT_EQ(got["summary"][0]["kind"], "tack");
  EXPECT_GE(got["summary"][0]["count"].get<int>(), 1);
  // The sim boat's IMU sails the course its fixes come from (the race scenario): the published
  // heel changes side through every tack listed.
  for (const auto& t : got["manoeuvres"]) {
    if (t["kind"] == "tack") {
      EXPECT_EQ(t["heel_flip_agrees"], true) << t.dump();
    }
  }

  const auto sessions = get_json("/api/v1/sessions?boat=tack1");
  const std::string base = "/api/v1/sessions/" + std::to_string(sessions[0]["id"].get<int>());
  const json est = get_json(base + "/manoeuvres");  // the wind estimated from the tack
  EXPECT_EQ(est["wind"]["given"], false);
  ASSERT_TRUE(est["wind"]["from_deg"].is_number()) << est.dump();
  auto c = client();
  auto csv = c.Get(base + "/manoeuvres?format=csv&wind_from_deg=255", bearer());
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->status, 200);
  EXPECT_EQ(csv->body.rfind("kind,t_utc,turn_deg", 0), 0u);
  EXPECT_NE(csv->body.find("\ntack,"), std::string::npos) << csv->body;
  auto bad = c.Get(base + "/manoeuvres?wind_from_deg=400", bearer());
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  auto none = c.Get("/api/v1/sessions/999999/manoeuvres", bearer());
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 404);

  // `from` (the fleet view's live poll): the manoeuvres from then on, computed from the data of
  // the 45 s before it, and how far the data reaches (a metric is final 20 s after t0). From the
  // session's start the tack is there, measured alike; from the end of the data it is not.
  const std::string start = sessions[0]["start"].get<std::string>();
  const json since = get_json(base + "/manoeuvres?wind_from_deg=255&from=" + start);
  ASSERT_FALSE(since["manoeuvres"].empty()) << since.dump();
  EXPECT_EQ(since["manoeuvres"][0]["kind"], "tack");
  EXPECT_NEAR(since["manoeuvres"][0]["turn_deg"].get<double>(), m["turn_deg"].get<double>(), 3.0);
  EXPECT_EQ(since["from_utc"], start);
  ASSERT_TRUE(since["data_to_utc"].is_string()) << since.dump();
  EXPECT_GT(since["data_to_utc"].get<std::string>(), m["t_utc"].get<std::string>());
  const json later = get_json(base + "/manoeuvres?from=" + since["data_to_utc"].get<std::string>());
  EXPECT_TRUE(later["manoeuvres"].empty()) << later.dump();
  auto bad_from = c.Get(base + "/manoeuvres?from=yesterday", bearer());
  ASSERT_TRUE(bad_from);
  EXPECT_EQ(bad_from->status, 400);
}

// The shore finds the tack itself, from the live samples, and pushes it on /api/v1/stream as
// an event of type "manoeuvre": first while measuring (final false), then final, with the fields
// of the REST row and the same values as the session's /manoeuvres.
TEST_F(ManoeuvreTest, TheStreamPushesTheTackFoundThenFinal) {
  auto c = client();
  c.set_read_timeout(10);
  std::vector<json> events;
  std::string buffer;
  const auto started = std::chrono::steady_clock::now();
  bool boat_started = false;
  auto res = c.Get("/api/v1/stream", bearer(), [&](const char* data, std::size_t len) {
    if (!boat_started) {  // the stream is open: nothing the boat sails is missed
      boat_started = true;
      start_boat("tack2", {"--seed", "10"});
    }
    buffer.append(data, len);
    std::size_t end;
    while ((end = buffer.find("\n\n")) != std::string::npos) {
      const std::string frame = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      const auto pos = frame.find("\ndata: ");
      if (frame.rfind("event: manoeuvre\n", 0) != 0 || pos == std::string::npos) continue;
      events.push_back(json::parse(frame.substr(pos + 7), nullptr, false));
    }
    for (const auto& e : events)
      if (e.is_object() && e["kind"] == "tack" && e["final"] == true) return false;
    return std::chrono::steady_clock::now() - started < 90s;
  });
  ASSERT_TRUE(boat_started) << "no stream";
  std::string seen;
  for (const auto& e : events) seen += e.dump() + "\n";
  const auto final_at = std::find_if(events.begin(), events.end(), [](const json& e) {
    return e.is_object() && e["kind"] == "tack" && e["final"] == true;
  });
  ASSERT_NE(final_at, events.end()) << "no final tack on the stream in 90 s:\n" << seen;
  const json& fin = *final_at;
  // Found first, measuring: the same manoeuvre (t0 within a few seconds) before the final one.
  const auto found = std::find_if(events.begin(), final_at, [](const json& e) {
    return e.is_object() && e["final"] == false;
  });
  ASSERT_NE(found, final_at) << "the tack came final at once:\n" << seen;
  EXPECT_EQ((*found)["boat_id"], "tack2");
  for (const char* field : {"boat_id", "kind", "t_utc", "turn_deg", "turn_dir", "distance_lost_m",
                            "heel_peak_deg", "entry_sog_m_s", "recovery_s", "final"})
    EXPECT_TRUE(fin.contains(field)) << field << " missing: " << fin.dump();
  EXPECT_EQ(fin["boat_id"], "tack2");
  EXPECT_TRUE(fin["distance_lost_m"].is_number()) << fin.dump();
  EXPECT_TRUE(fin["heel_peak_deg"].is_number()) << fin.dump();

  // The review of the session: the same tack, the same t0 and metrics.
  json rest;
  ASSERT_TRUE(eventually(
      [&] {
        const auto s = get_json("/api/v1/sessions?boat=tack2");
        if (!s.is_array() || s.empty()) return false;
        rest = get_json("/api/v1/sessions/" + std::to_string(s[0]["id"].get<int>()) +
                        "/manoeuvres");
        return rest.is_object() && !rest["manoeuvres"].empty();
      },
      10s))
      << rest.dump();
  const auto& m = rest["manoeuvres"][0];
  EXPECT_EQ(m["kind"], "tack");
  EXPECT_EQ(m["t_utc"], fin["t_utc"]) << m.dump() << "\n" << fin.dump();
  EXPECT_NEAR(m["turn_deg"].get<double>(), fin["turn_deg"].get<double>(), 0.1);
  EXPECT_NEAR(m["distance_lost_m"].get<double>(), fin["distance_lost_m"].get<double>(), 0.05);
  EXPECT_NEAR(m["heel_peak_deg"].get<double>(), fin["heel_peak_deg"].get<double>(), 0.05);
  // The row's every field, no more (one definition of the record), plus boat_id and final.
  for (const auto& [k, v] : m.items()) EXPECT_TRUE(fin.contains(k)) << k;
  EXPECT_EQ(fin.size(), m.size() + 2);
}

}  // namespace
}  // namespace telltale::testing
