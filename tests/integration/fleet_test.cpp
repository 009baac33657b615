// Walking skeleton over real processes: a shore_server and two boat_nodes on a private DDS domain;
// the fleet seen over HTTP, live over SSE, and recorded in SQLite.
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>
#include <sqlite3.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <thread>

#include "dds_participant.hpp"
#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

using FleetTest = ShoreFixture;

// Given a shore and two boats on a private domain, when a few seconds pass, then both boats are
// listed over HTTP with finite heel and pitch that change between two reads.
TEST_F(FleetTest, TwoBoatsAppearWithLiveChangingAttitude) {
  start_boat("alpha");
  start_boat("bravo-2");

  std::map<std::string, json> first;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (std::chrono::steady_clock::now() < deadline) {
    first = boats_by_id();
    if (first.size() == 2) break;
    std::this_thread::sleep_for(200ms);
  }
  ASSERT_EQ(first.size(), 2u) << "shore output: " << shore_->output();
  std::this_thread::sleep_for(1s);
  const auto second = boats_by_id();
  for (const char* id : {"alpha", "bravo-2"}) {
    SCOPED_TRACE(id);
    ASSERT_TRUE(second.count(id));
    const json& a = first.at(id);
    const json& b = second.at(id);
    ASSERT_TRUE(b["heel_deg"].is_number());
    ASSERT_TRUE(b["pitch_deg"].is_number());
    EXPECT_TRUE(std::isfinite(b["heel_deg"].get<double>()));
    EXPECT_TRUE(std::isfinite(b["pitch_deg"].get<double>()));
    EXPECT_LT(std::abs(b["heel_deg"].get<double>()), 90.0);
    EXPECT_LT(std::abs(b["pitch_deg"].get<double>()), 90.0);
    EXPECT_GT(b["seq"].get<std::uint64_t>(), a["seq"].get<std::uint64_t>());
    EXPECT_NE(b["heel_deg"].get<double>(), a["heel_deg"].get<double>());
    EXPECT_NE(b["pitch_deg"].get<double>(), a["pitch_deg"].get<double>());
    EXPECT_FALSE(b["stale"].get<bool>());
    // 25 Hz for one second: the sequence advanced by about 25 (best effort on loopback).
    EXPECT_GE(b["seq"].get<std::uint64_t>() - a["seq"].get<std::uint64_t>(), 20u);
  }
}

// Given two boat nodes configured with one id, then the boat's card carries a duplicate_id
// problem naming both runs and /healthz lists the id; once one node stops, the flag clears.
TEST_F(FleetTest, TwoNodesWithOneIdAreFlaggedOnTheCardAndInHealthz) {
  start_boat("twin", {"--log-dir", dir_ + "/log_twin_a"});
  Process& second = start_boat("twin", {"--log-dir", dir_ + "/log_twin_b"});
  json card;
  EXPECT_TRUE(eventually(
      [&] {
        const auto boats = boats_by_id();
        if (!boats.count("twin")) return false;
        card = boats.at("twin");
        return card["duplicate_id"].get<bool>();
      },
      15s))
      << card;
  ASSERT_FALSE(card["problems"].empty()) << card;
  EXPECT_EQ(card["problems"][0]["code"], "duplicate_id") << card;
  json health;
  EXPECT_TRUE(eventually(
      [&] {
        auto res = client().Get("/healthz");
        if (!res || res->status != 200) return false;
        health = json::parse(res->body);
        return health.contains("duplicate_boat_ids") &&
               health["duplicate_boat_ids"][0]["boat_id"] == "twin" &&
               health["boat_problems"].contains("duplicate_id") &&
               health["boat_problems"]["duplicate_id"][0] == "twin";
      },
      15s))
      << health;
  // Recorded apart: the second node's run under an id of its own, with its track.
  json sessions;
  EXPECT_TRUE(eventually(
      [&] {
        sessions = get_json("/api/v1/sessions");
        std::set<std::string> ids;
        for (const auto& s : sessions) ids.insert(s["boat_id"].get<std::string>());
        return ids.size() == 2 && ids.count("twin") &&
               std::any_of(ids.begin(), ids.end(),
                           [](const std::string& id) { return id.rfind("twin-", 0) == 0; });
      },
      10s))
      << sessions;
  EXPECT_EQ(second.stop(SIGINT), 0);
  EXPECT_TRUE(eventually(
      [&] {
        card = boats_by_id().at("twin");
        return !card["duplicate_id"].get<bool>() && card["problems"].empty();
      },
      20s))
      << card;
}

// The live stream pushes samples of every boat; a boat that stops goes stale within 2.5 s.
TEST_F(FleetTest, StreamDeliversSamplesAndMarksSilentBoatStale) {
  start_boat("charlie");
  Process& delta = start_boat("delta");

  std::map<std::string, int> samples;
  bool delta_stale = false;
  bool stopped_delta = false;
  auto started = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point stop_time;
  auto c = client();
  c.set_read_timeout(20);
  std::string buffer;
  auto res = c.Get("/api/v1/stream", {{"Authorization", std::string("Bearer ") + kCoachToken}},
                   [&](const char* data, std::size_t len) {
                     buffer.append(data, len);
                     std::size_t end;
                     while ((end = buffer.find("\n\n")) != std::string::npos) {
                       const std::string frame = buffer.substr(0, end);
                       buffer.erase(0, end + 2);
                       const auto pos = frame.find("data: ");
                       if (frame.rfind("event: sample", 0) != 0 || pos == std::string::npos)
                         continue;
                       const json b = json::parse(frame.substr(pos + 6));
                       const std::string id = b["id"];
                       ++samples[id];
                       if (stopped_delta && id == "delta" && b["stale"].get<bool>())
                         delta_stale = true;
                     }
                     const auto now = std::chrono::steady_clock::now();
                     if (!stopped_delta && samples["charlie"] > 25 && samples["delta"] > 25) {
                       EXPECT_EQ(delta.stop(SIGKILL), 128 + SIGKILL);
                       stopped_delta = true;
                       stop_time = now;
                     }
                     if (delta_stale) return false;
                     return now - started < 30s;
                   });
  ASSERT_TRUE(stopped_delta) << "samples: charlie " << samples["charlie"] << " delta "
                             << samples["delta"];
  EXPECT_TRUE(delta_stale) << "delta never went stale";
  EXPECT_LT(std::chrono::steady_clock::now() - stop_time, 3500ms);
}

// A wearable node's athlete appears beside the boats with steps that grow.
TEST_F(FleetTest, WearableAthleteAppearsAndWalks) {
  Process walker(
      {bin_dir() + "/wearable_node", "--domain", std::to_string(domain_), "--athlete-id", "ann"});
  ASSERT_TRUE(walker.wait_for_line("wearable_node ready: ", 20s)) << walker.output();
  nlohmann::json first;
  ASSERT_TRUE(eventually(
      [&] {
        first = get_json("/api/v1/athletes");
        return first.is_array() && first.size() == 1;
      },
      15s));
  EXPECT_EQ(first[0]["id"], "ann");
  EXPECT_EQ(first[0]["kind"], "wearable");
  ASSERT_TRUE(eventually(
      [&] {
        const auto now = get_json("/api/v1/athletes");
        return now.is_array() && now.size() == 1 &&
               now[0]["steps"].get<int>() > first[0]["steps"].get<int>() + 3;
      },
      15s));
  const auto track = get_json("/api/v1/athletes/ann/track");
  EXPECT_GE(track["x_m"].size(), 4u);
  EXPECT_EQ(walker.stop(SIGINT), 0);
}

// A belt sensor's athlete (wearable_node --mount trunk, each step measured from the trunk's rise
// and fall) reaches the shore over DDS as the trunk pose, walking: the IDL's newest pose value on
// the real wire.
TEST_F(FleetTest, TrunkMountedAthleteArrivesAsTheTrunkPose) {
  Process walker({bin_dir() + "/wearable_node", "--domain", std::to_string(domain_), "--athlete-id",
                  "bea", "--mount", "trunk", "--height-m", "1.68"});
  ASSERT_TRUE(walker.wait_for_line("wearable_node ready: ", 20s)) << walker.output();
  nlohmann::json now;
  ASSERT_TRUE(eventually(
      [&] {
        now = get_json("/api/v1/athletes");
        return now.is_array() && now.size() == 1 && now[0]["steps"].get<int>() > 4 &&
               now[0]["distance_m"].is_number() && now[0]["distance_m"].get<double>() > 1.0;
      },
      20s))
      << now.dump();
  EXPECT_EQ(now[0]["id"], "bea");
  EXPECT_EQ(now[0]["pose"], "trunk");
  EXPECT_EQ(walker.stop(SIGINT), 0);
}

TEST_F(FleetTest, AuthAndOpenEndpoints) {
  auto c = client();
  auto health = c.Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  EXPECT_EQ(json::parse(health->body)["status"], "ok");

  auto spec = c.Get("/api/v1/openapi.json");
  ASSERT_TRUE(spec);
  ASSERT_EQ(spec->status, 200);
  const json doc = json::parse(spec->body);
  for (const char* path :
       {"/healthz", "/api/v1/boats", "/api/v1/stream", "/api/v1/login", "/api/v1/boats/{id}/track",
        "/api/v1/sessions/{id}/gpx", "/api/v1/sessions/{id}/heel_speed"})
    EXPECT_TRUE(doc["paths"].contains(path)) << path;

  for (const auto& headers :
       {httplib::Headers{}, httplib::Headers{{"Authorization", "Bearer wrong"}},
        httplib::Headers{{"Authorization", "Basic abc"}}}) {
    auto res = c.Get("/api/v1/boats", headers);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 401);
    EXPECT_TRUE(json::parse(res->body).contains("error"));
  }
  auto missing =
      c.Get("/api/v1/nothing-here", {{"Authorization", std::string("Bearer ") + kCoachToken}});
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_TRUE(json::parse(missing->body).contains("error"));

  // Login exchanges the bearer token for an HttpOnly cookie that then authorises requests.
  auto login = c.Post("/api/v1/login", {{"Authorization", std::string("Bearer ") + kCoachToken}},
                      "", "text/plain");
  ASSERT_TRUE(login);
  EXPECT_EQ(login->status, 200);
  const std::string cookie = login->get_header_value("Set-Cookie");
  EXPECT_NE(cookie.find("HttpOnly"), std::string::npos);
  auto with_cookie = c.Get("/api/v1/boats", {{"Cookie", cookie.substr(0, cookie.find(';'))}});
  ASSERT_TRUE(with_cookie);
  EXPECT_EQ(with_cookie->status, 200);

  auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("Telltale"), std::string::npos);
}

// SIGINT stops every process cleanly (exit 0) and the shore has recorded both boats' samples.
TEST_F(FleetTest, CleanShutdownKeepsTheRecording) {
  Process& echo = start_boat("echo");
  std::this_thread::sleep_for(3s);
  EXPECT_EQ(echo.stop(SIGINT), 0);
  const auto stopped = echo.wait_for_line("boat_node stopped: ", 1s);
  ASSERT_TRUE(stopped) << echo.output();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(*stopped, m, std::regex(R"(published=(\d+))")));
  const long published = std::stol(m[1]);
  EXPECT_GT(published, 50);
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(shore_->stop(SIGTERM), 0) << shore_->output();
  // A clean close checkpoints the WAL and removes it: no stale state left behind.
  EXPECT_FALSE(std::filesystem::exists(db_path() + "-wal"));
  EXPECT_FALSE(std::filesystem::exists(db_path() + "-shm"));

  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2((db_path()).c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "SELECT COUNT(*), MAX(seq) FROM attitude WHERE boat_id = 'echo'", -1, &st,
                     nullptr);
  ASSERT_EQ(sqlite3_step(st), SQLITE_ROW);
  const long stored = sqlite3_column_int64(st, 0);
  const long max_seq = sqlite3_column_int64(st, 1);
  sqlite3_finalize(st);
  sqlite3_close(db);
  // Everything the shore received after discovery is stored; the last one published is there.
  EXPECT_EQ(max_seq, published);
  EXPECT_GT(stored, published / 2);
}

// A first run needs no flags: the database goes in the user's data folder and the printed link
// logs a browser in (and opens the fleet map).
TEST(FirstRun, ShoreWithNoFlagsPrintsALoginLinkAndKeepsItsDatabaseInTheDataFolder) {
  const std::string home = make_temp_dir();
  Process shore({bin_dir() + "/shore_server", "--http-port", "0", "--domain",
                 std::to_string(unique_domain())},
                {"HOME=" + home, "XDG_DATA_HOME=", "TELLTALE_COACH_TOKEN="});
  const auto link = shore.wait_for_line("shore_server dashboard: ", std::chrono::seconds(20));
  ASSERT_TRUE(link) << shore.output();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      *link, m, std::regex(R"(http://127\.0\.0\.1:(\d+)/#token=([A-Za-z0-9_-]+)&view=map)")))
      << *link;
  httplib::Client c("127.0.0.1", std::stoi(m[1]));
  auto login =
      c.Post("/api/v1/login", {{"Authorization", "Bearer " + m[2].str()}}, "", "text/plain");
  ASSERT_TRUE(login);
  EXPECT_EQ(login->status, 200);
  EXPECT_TRUE(std::filesystem::exists(home + "/.local/share/telltale/telltale.db"))
      << shore.output();
  EXPECT_EQ(shore.stop(SIGINT), 0);
  std::filesystem::remove_all(home);
}

// Given a running shore, when a node's participant joins fifteen times over, then each time it
// meets the shore within 0.8 s. The shore announces itself again 50 ms after each newcomer
// (join_announcer.hpp); without that, about a third of joins miss the shore's first answer and
// wait for its periodic announcement, up to 2 s (seen: 0.3-1.9 s in those joins).
TEST_F(FleetTest, ANodeJoiningMeetsTheShoreWithoutWaitingForItsPeriodicAnnouncement) {
  struct Meet : eprosima::fastdds::dds::DomainParticipantListener {
    std::atomic<bool> met{false};
    void on_participant_discovery(
        eprosima::fastdds::dds::DomainParticipant*,
        eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
      if (info.status ==
              eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT &&
          info.info.m_participantName.to_string() == "shore_server")
        met = true;
    }
  };
  std::this_thread::sleep_for(1s);  // the shore's own start-up announcements are over
  std::vector<double> waits;
  for (int i = 0; i < 15; ++i) {
    Meet meet;
    dds::DdsOptions opts;
    opts.domain = domain_;
    opts.listener = &meet;
    const auto t0 = std::chrono::steady_clock::now();
    auto node = std::make_unique<dds::Participant>(opts, "joining-node");
    while (!meet.met && std::chrono::steady_clock::now() - t0 < 3s)
      std::this_thread::sleep_for(2ms);
    waits.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    node.reset();
    std::this_thread::sleep_for(300ms);  // joins apart: each gets an announcement of its own
  }
  for (std::size_t i = 0; i < waits.size(); ++i)
    EXPECT_LT(waits[i], 0.8) << "join " << i << " met the shore after " << waits[i] << " s";
}

}  // namespace
}  // namespace telltale::testing
