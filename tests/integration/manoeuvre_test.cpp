// Manoeuvres end to end: a simulated boat sails its race course (seed 10 tacks ~28 s
// after the start) into a real shore; the session's /manoeuvres lists the tack, in JSON and CSV.
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
        for (const auto& m : got["manoeuvres"])
          if (m["kind"] == "tack") return true;
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

}  // namespace
}  // namespace telltale::testing
