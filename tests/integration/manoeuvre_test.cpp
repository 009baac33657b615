// Manoeuvres end to end (issue 21): a simulated boat sails its race course (seed 10 tacks ~28 s
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
}

}  // namespace
}  // namespace telltale::testing
