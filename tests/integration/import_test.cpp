// Imports over real HTTP against a real shore_server: upload, progress and result, the sessions
// listed, exported and read back as GPX, re-import as a no-op, a cut file storing nothing, the
// roles, the limits and the live stream's import events.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <thread>

#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

constexpr const char* kAnalyst = "import-analyst";
constexpr const char* kAthlete = "import-athlete";
constexpr long kT0s = 1795300000;

/// An Atlas CSV (UTC offset +01:00) of `n` rows at 2 Hz.
std::string atlas_csv(std::size_t n) {
  std::string out = "timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\r\n";
  char line[160];
  for (std::size_t i = 0; i < n; ++i) {
    const std::time_t secs = kT0s + 3600 + static_cast<std::time_t>(i / 2);
    std::tm tm{};
    gmtime_r(&secs, &tm);
    std::snprintf(line, sizeof line,
                  "%04d-%02d-%02dT%02d:%02d:%02d.%03d+01:00,%.7f,%.7f,5.0,45.0,47.0,%.1f,6.0\r\n",
                  tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                  i % 2 ? 500 : 0, 39.5 + 1e-6 * static_cast<double>(i),
                  2.5 + 1e-6 * static_cast<double>(i), 10.0 * std::sin(0.05 * static_cast<double>(i)));
    out += line;
  }
  return out;
}

class ImportTest : public ShoreFixture {
 protected:
  std::vector<std::string> shore_flags() const override {
    return {"--analyst-token", kAnalyst, "--athlete-token", std::string("ILCA-9:") + kAthlete,
            "--max-import-mb", "1"};
  }
  httplib::Result upload(const std::string& query, const std::string& body,
                         const std::string& token = kCoachToken) const {
    auto c = client();
    return c.Post("/api/v1/imports?" + query, bearer(token), body, "application/octet-stream");
  }
  /// Waits for the import to finish; its last state.
  nlohmann::json finished(std::int64_t id) const {
    nlohmann::json j;
    eventually(
        [&] {
          j = get_json("/api/v1/imports/" + std::to_string(id));
          return j.is_object() && j["state"] != "running";
        },
        std::chrono::seconds(20));
    return j;
  }
};

TEST_F(ImportTest, AtlasCsvBecomesAReviewableSessionAndReimportChangesNothing) {
  // The live stream, to see the import's events.
  std::atomic<bool> saw_running{false}, saw_done{false}, stop{false};
  std::thread stream([&] {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(30);
    std::string buf;
    c.Get("/api/v1/stream", bearer(), [&](const char* data, std::size_t n) {
      buf.append(data, n);
      if (buf.find("event: import") != std::string::npos) {
        if (buf.find("\"state\":\"running\"") != std::string::npos) saw_running = true;
        if (buf.find("\"state\":\"done\"") != std::string::npos) saw_done = true;
      }
      return !stop.load();
    });
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));

  const std::string csv = atlas_csv(1200);  // 10 minutes
  auto res = upload("boat=ILCA-7&name=race1.csv", csv, kAnalyst);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const auto id = nlohmann::json::parse(res->body)["id"].get<std::int64_t>();
  EXPECT_EQ(res->get_header_value("Location"), "/api/v1/imports/" + std::to_string(id));
  const auto done = finished(id);
  ASSERT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(done["format"], "vakaros_csv");
  EXPECT_EQ(done["file_name"], "race1.csv");
  EXPECT_EQ(done["points"], 1200);
  EXPECT_EQ(done["samples_added"], 1200);
  EXPECT_EQ(done["bytes_read"], csv.size());
  ASSERT_EQ(done["sessions"].size(), 1u);
  const auto session = done["sessions"][0].get<std::int64_t>();

  const auto sessions = get_json("/api/v1/sessions?boat=ILCA-7");
  ASSERT_TRUE(sessions.is_array());
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0]["id"], session);
  auto c = client();
  auto exported = c.Get("/api/v1/sessions/" + std::to_string(session) + "/export?format=csv", bearer());
  ASSERT_TRUE(exported);
  ASSERT_EQ(exported->status, 200);
  EXPECT_EQ(std::count(exported->body.begin(), exported->body.end(), '\n'), 1201);
  auto gpx = c.Get("/api/v1/sessions/" + std::to_string(session) + "/gpx", bearer());
  ASSERT_TRUE(gpx);
  EXPECT_EQ(gpx->status, 200);
  EXPECT_NE(gpx->body.find("<trkpt"), std::string::npos);

  // The same file again: nothing new, the same session.
  res = upload("boat=ILCA-7&name=copy.csv", csv);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202);
  const auto again = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  EXPECT_EQ(again["state"], "done");
  EXPECT_EQ(again["duplicate_of"], id);
  EXPECT_EQ(again["samples_added"], 0);
  EXPECT_EQ(again["sessions"], done["sessions"]);
  EXPECT_EQ(get_json("/api/v1/sessions?boat=ILCA-7").size(), 1u);
  // The session's sources: both uploads of the file, newest first.
  const auto sources = get_json("/api/v1/imports?session=" + std::to_string(session));
  ASSERT_TRUE(sources.is_array());
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources[1]["id"], id);
  EXPECT_EQ(sources[1]["file_name"], "race1.csv");
  EXPECT_EQ(sources[1]["sha256"].get<std::string>().size(), 64u);

  EXPECT_TRUE(eventually([&] { return saw_running.load() && saw_done.load(); },
                         std::chrono::seconds(5)));
  stop = true;
  shore_.reset();  // ends the stream
  stream.join();
}

/// A Velocitek VTK file: its device description (serial 4321), then `n` trackpoints at 1 Hz.
std::string vtk_file(int n) {
  auto varint = [](std::string& s, std::uint64_t v) {
    for (; v >= 0x80; v >>= 7) s.push_back(static_cast<char>((v & 0x7F) | 0x80));
    s.push_back(static_cast<char>(v));
  };
  auto record = [&](unsigned field, const std::string& body) {
    std::string rec, out;
    varint(rec, (field << 3) | 2);
    varint(rec, body.size());
    rec += body;
    out.push_back(static_cast<char>(rec.size() & 0xFF));
    out.push_back(static_cast<char>(rec.size() >> 8));
    return out + rec;
  };
  std::string hw;
  varint(hw, 4 << 3);
  varint(hw, 4321);
  std::string out = record(17, hw);
  for (int i = 0; i < n; ++i) {
    std::string tp;
    varint(tp, 1 << 3);
    varint(tp, static_cast<std::uint64_t>(kT0s + i));
    varint(tp, 3 << 3);
    varint(tp, 2ULL * 395000000);  // zigzag of a positive sint32
    varint(tp, 4 << 3);
    varint(tp, 2ULL * 25000000);
    out += record(1, tp);
  }
  return out;
}

TEST_F(ImportTest, VelocitekFileWithoutABoatGoesToItsSerial) {
  auto res = upload("name=prostart.vtk", vtk_file(30));
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const auto r = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  EXPECT_EQ(r["state"], "done") << r.dump();
  EXPECT_EQ(r["format"], "vtk");
  EXPECT_EQ(r["boat_id"], "velocitek-4321");
  EXPECT_EQ(r["device"], "Velocitek model 0 serial 4321");
  EXPECT_EQ(r["points"], 30);
  EXPECT_EQ(r["fixes_added"], 30);
  EXPECT_EQ(get_json("/api/v1/sessions?boat=velocitek-4321").size(), 1u);
}

TEST_F(ImportTest, FileOverlappingALiveBoatMergesIntoItsSession) {
  start_boat("ILCA-6");
  nlohmann::json live;
  ASSERT_TRUE(eventually(
      [&] {
        live = get_json("/api/v1/sessions?boat=ILCA-6");
        return live.is_array() && live.size() == 1 && live[0]["samples"].get<int>() > 100;
      },
      std::chrono::seconds(20)));
  boats_.clear();  // the boat stops: its session is what it is
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  live = get_json("/api/v1/sessions?boat=ILCA-6");
  ASSERT_EQ(live.size(), 1u);
  const int live_samples = live[0]["samples"];
  // The same boat's instrument log: from 20 s before the live data to 20 s after, at 2 Hz.
  const auto start = live[0]["start"].get<std::string>();
  const auto end = live[0]["end"].get<std::string>();
  auto secs = [](const std::string& iso) {
    std::tm tm{};
    strptime(iso.c_str(), "%Y-%m-%dT%H:%M:%S", &tm);
    return static_cast<long>(timegm(&tm));
  };
  const long from = secs(start) - 20, to = secs(end) + 20;
  std::string csv = "timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\n";
  char line[160];
  for (long t = from; t <= to; ++t)
    for (int half = 0; half < 2; ++half) {
      const std::time_t tt = t;
      std::tm tm{};
      gmtime_r(&tt, &tm);
      std::snprintf(line, sizeof line,
                    "%04d-%02d-%02dT%02d:%02d:%02d.%03d+00:00,39.5,2.5,5.0,45.0,47.0,4.0,6.0\n",
                    tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min,
                    tm.tm_sec, half ? 500 : 0);
      csv += line;
    }
  const std::size_t rows = static_cast<std::size_t>(to - from + 1) * 2;
  auto res = upload("boat=ILCA-6", csv);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const auto r = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  ASSERT_EQ(r["state"], "done") << r.dump();
  EXPECT_EQ(r["points"], rows);
  const auto merged = get_json("/api/v1/sessions?boat=ILCA-6");
  ASSERT_EQ(merged.size(), 1u) << merged.dump();
  EXPECT_EQ(merged[0]["id"], live[0]["id"]);
  EXPECT_EQ(merged[0]["samples"].get<int>(), live_samples + r["samples_added"].get<int>());
  // A file row at the instant of a live sample is not added (the live one stays): never doubled.
  const auto added = r["samples_added"].get<std::size_t>();
  EXPECT_LE(added, rows);
  EXPECT_GT(added, rows / 2);
  auto c = client();
  auto exported = c.Get("/api/v1/sessions/" + std::to_string(merged[0]["id"].get<int>()) +
                            "/export?format=csv",
                        bearer());
  ASSERT_TRUE(exported);
  EXPECT_EQ(std::count(exported->body.begin(), exported->body.end(), '\n') - 1,
            static_cast<long>(live_samples) + static_cast<long>(added));
}

TEST_F(ImportTest, CutFileFailsNamingTheLineAndStoresNothing) {
  std::string csv = atlas_csv(100);
  csv.resize(csv.size() - 20);
  auto res = upload("boat=ILCA-8", csv);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202);
  const auto r = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  EXPECT_EQ(r["state"], "failed");
  EXPECT_NE(r["error"].get<std::string>().find("line 101"), std::string::npos) << r.dump();
  EXPECT_EQ(get_json("/api/v1/sessions?boat=ILCA-8").size(), 0u);
}

TEST_F(ImportTest, RolesParametersAndLimits) {
  const std::string csv = atlas_csv(10);
  auto res = upload("boat=ILCA-9", csv, kAthlete);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  auto c = client();
  res = c.Post("/api/v1/imports?boat=ILCA-9", csv, "text/csv");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 401);
  for (const std::string q : {"", "boat=bad%20id", "boat=B&format=fit", "boat=B&tz=Mars/Olympus",
                              "boat=B&heel_offset=x", "boat=B&pitch_offset=99", "boat=B&color=red"}) {
    res = upload(q, csv);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 400) << q << ": " << res->body;
    EXPECT_NE(res->body.find("\"error\""), std::string::npos);
  }
  res = upload("boat=B", "");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  res = upload("boat=B", std::string((1 << 20) + 1, 'x'));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 413);
  // The old Atlas dialect with the time zone given; a forced format.
  const std::string old =
      "timestamp,latitude,longitude,sog_kts,cog,hdg_true,roll,pitch\n"
      "2026-11-22T11:00:00.000,41.73877,12.24574,3.0,113.1,125.4,-1.7,4.6\n";
  res = upload("boat=B&tz=Europe/Rome&format=vakaros_csv&pitch_offset=6", old);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const auto r = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  EXPECT_EQ(r["state"], "done") << r.dump();
  EXPECT_EQ(r["start"], "2026-11-22T10:00:00.000Z");
  // Athletes see their own boat's imports only.
  auto mine = c.Get("/api/v1/imports/" + std::to_string(r["id"].get<int>()), bearer(kAthlete));
  ASSERT_TRUE(mine);
  EXPECT_EQ(mine->status, 403);
  EXPECT_EQ(c.Get("/api/v1/imports/999", bearer())->status, 404);
}

TEST_F(ImportTest, CommandLineUploaderImportsAFolder) {
  const std::string folder = dir_ + "/logs";
  std::filesystem::create_directories(folder + "/day2");
  std::string cut = atlas_csv(30);
  cut.resize(cut.size() - 20);
  std::ofstream(folder + "/a_good.csv", std::ios::binary) << atlas_csv(40);
  std::ofstream(folder + "/day2/b_cut.csv", std::ios::binary) << cut;
  Process cli({bin_dir() + "/telltale_import", folder, "--shore",
               "http://127.0.0.1:" + std::to_string(port_), "--boat", "ILCA-3"},
              {std::string("TELLTALE_TOKEN=") + kCoachToken});
  ASSERT_TRUE(cli.wait_for_line("2 files, 1 imported, 1 failed", std::chrono::seconds(30)))
      << cli.output();
  EXPECT_TRUE(eventually([&] { return !cli.running(); }, std::chrono::seconds(10)));
  EXPECT_EQ(cli.stop(SIGTERM), 1);
  EXPECT_NE(cli.output().find("a_good.csv: done, vakaros_csv, 40 points, sessions "),
            std::string::npos)
      << cli.output();
  EXPECT_NE(cli.output().find("b_cut.csv: failed: vakaros_csv: line 31"), std::string::npos)
      << cli.output();
  EXPECT_EQ(get_json("/api/v1/sessions?boat=ILCA-3").size(), 1u);
  // No token: one line, a non-zero exit.
  Process none({bin_dir() + "/telltale_import", folder, "--boat", "ILCA-3"});
  EXPECT_TRUE(eventually([&] { return !none.running(); }, std::chrono::seconds(10)));
  EXPECT_EQ(none.stop(SIGTERM), 2);
}

}  // namespace
}  // namespace telltale::testing
