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

// Real watch tracks (tests/data/maxsail_valencia: a dinghy's two races, positions only at 1 Hz):
// imported as the watch wrote them, the session gets speed and course from the positions and its
// manoeuvres: every tack and gybe the track shows after the start (its course, read every 5 s:
// steady courses on either side of a turn), at its time and through its angle, nothing else
// called a tack or gybe after the start, and the wind within the estimate's reach of the 110 deg
// the sailor noted for both races.
struct SeenTurn {
  const char* t_utc;  // the middle of the turn as the track shows it
  const char* kind;
  double turn_deg;  // between the steady courses either side
};

/// a - b in seconds, both "YYYY-MM-DDThh:mm:ss[.fff][Z]".
double seconds_apart(const std::string& a, const std::string& b) {
  const auto secs = [](const std::string& iso) {
    std::tm tm{};
    const char* rest = strptime(iso.c_str(), "%Y-%m-%dT%H:%M:%S", &tm);
    double frac = 0.0;
    if (rest && *rest == '.') frac = std::strtod(rest, nullptr);
    return static_cast<double>(timegm(&tm)) + frac;
  };
  return secs(a) - secs(b);
}

/// The track as a watch's GPX 1.1 (positions and times only).
std::string watch_gpx(const std::string& csv_path) {
  std::ifstream in(csv_path);
  std::string line, out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<gpx creator=\"Garmin Connect\" version=\"1.1\" "
      "xmlns=\"http://www.topografix.com/GPX/1/1\">\n<trk><name>race</name><trkseg>\n";
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    const auto a = line.find(','), b = line.find(',', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    out += "<trkpt lat=\"" + line.substr(a + 1, b - a - 1) + "\" lon=\"" + line.substr(b + 1) +
           "\"><time>" + line.substr(0, a) + "</time></trkpt>\n";
  }
  return out + "</trkseg></trk></gpx>\n";
}

TEST_F(ImportTest, RealWatchTracksGiveTheirTacksAndTheWind) {
  struct Race {
    const char* file;
    const char* boat;
    const char* start_utc;  // 5 minutes into the file (the sailor's note)
    std::vector<SeenTurn> seen;
  };
  const Race races[] = {
      {"ESP30782-P01.csv", "ESP30782-R1", "2025-06-21T11:23:29", {
        {"2025-06-21T11:26:42", "tack", 88.0},
        {"2025-06-21T11:30:32", "tack", 95.0},
        {"2025-06-21T11:31:50", "gybe", 132.0},  // the windward mark: bear away and gybe
        {"2025-06-21T11:37:10", "gybe", 85.0},   // the leeward mark, then up to close-hauled
        {"2025-06-21T11:37:42", "tack", 82.0},
        {"2025-06-21T11:38:35", "tack", 112.0},  // two tacks 15 s apart
        {"2025-06-21T11:38:50", "tack", 112.0},
        {"2025-06-21T11:40:34", "tack", 82.0},
        {"2025-06-21T11:43:42", "tack", 80.0},
        {"2025-06-21T11:51:00", "tack", 180.0}}},
      {"ESP30782-P02.csv", "ESP30782-R2", "2025-06-21T12:06:29", {
        {"2025-06-21T12:09:59", "tack", 92.0},
        {"2025-06-21T12:10:16", "tack", 95.0},
        {"2025-06-21T12:12:21", "tack", 86.0},
        {"2025-06-21T12:21:30", "gybe", 140.0},  // the leeward mark: gybe and up in one turn
        {"2025-06-21T12:22:04", "tack", 88.0},
        {"2025-06-21T12:23:14", "tack", 80.0},
        {"2025-06-21T12:26:32", "tack", 100.0},
        {"2025-06-21T12:27:27", "tack", 82.0},
        {"2025-06-21T12:28:19", "tack", 87.0},
        {"2025-06-21T12:30:36", "gybe", 125.0},  // the windward mark: bear away and gybe
        {"2025-06-21T12:39:11", "tack", 195.0}}},
  };
  for (const Race& race : races) {
    SCOPED_TRACE(race.file);
    const std::string gpx = watch_gpx(std::string(TELLTALE_TEST_DATA_DIR) + "/maxsail_valencia/" + race.file);
    auto res = upload(std::string("boat=") + race.boat + "&name=" + race.file, gpx, kAnalyst);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 202) << res->body;
    const auto done = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
    ASSERT_EQ(done["state"], "done") << done.dump();
    EXPECT_EQ(done["format"], "gpx");
    ASSERT_EQ(done["sessions"].size(), 1u) << done.dump();
    const auto session = done["sessions"][0].get<std::int64_t>();
    const auto got = get_json("/api/v1/sessions/" + std::to_string(session) + "/manoeuvres");
    ASSERT_TRUE(got["manoeuvres"].is_array()) << got.dump();
    ASSERT_TRUE(got["wind"]["from_deg"].is_number()) << got.dump();
    const double wind = got["wind"]["from_deg"].get<double>();
    EXPECT_LT(std::abs(std::remainder(wind - 110.0, 360.0)), 8.0) << "wind " << wind;
    std::vector<bool> matched(got["manoeuvres"].size(), false);
    for (const SeenTurn& s : race.seen) {
      bool found = false;
      for (std::size_t i = 0; i < got["manoeuvres"].size(); ++i) {
        const auto& m = got["manoeuvres"][i];
        const std::string t = m["t_utc"].get<std::string>();
        if (matched[i] || m["kind"] != s.kind) continue;
        if (std::abs(seconds_apart(t, s.t_utc)) > 6.0) continue;
        matched[i] = found = true;
        EXPECT_NEAR(m["turn_deg"].get<double>(), s.turn_deg, 12.0) << s.kind << " at " << s.t_utc;
        EXPECT_TRUE(m["distance_lost_m"].is_number()) << s.kind << " at " << s.t_utc;
        break;
      }
      EXPECT_TRUE(found) << "not found: " << s.kind << " at " << s.t_utc << "\n" << got.dump();
    }
    for (std::size_t i = 0; i < got["manoeuvres"].size(); ++i) {
      const auto& m = got["manoeuvres"][i];
      const bool after_start = seconds_apart(m["t_utc"].get<std::string>(), race.start_utc) > 0.0;
      if (matched[i] || !after_start || (m["kind"] != "tack" && m["kind"] != "gybe")) continue;
      ADD_FAILURE() << "not in the track: " << m.dump();
    }
  }
}

/// The first race's track as an NMEA log from a boat with a GPS and a masthead wind instrument:
/// RMC (position, SOG and COG from the neighbouring positions, as a receiver gives them) and MWV R,
/// the apparent wind such an instrument would read in a true wind from `wind_from(t_s)` at 6 m/s
/// (the air over the ground minus the boat's own velocity, turned to the bow by the COG).
std::string instrument_nmea(const std::string& csv_path, double (*wind_from)(double)) {
  struct P {
    std::string t;
    double lat, lon;
  };
  std::vector<P> pts;
  std::ifstream in(csv_path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const auto a = line.find(','), b = line.find(',', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    pts.push_back({line.substr(0, a), std::stod(line.substr(a + 1, b - a - 1)),
                   std::stod(line.substr(b + 1))});
  }
  const auto sentence = [](const std::string& body) {
    unsigned sum = 0;
    for (char c : body) sum ^= static_cast<unsigned char>(c);
    char tail[8];
    std::snprintf(tail, sizeof tail, "*%02X", sum);
    return "$" + body + tail + "\r\n";
  };
  const auto dm = [](double deg, int deg_digits) {
    const double a = std::abs(deg);
    const int d = static_cast<int>(a);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%0*d%09.6f", deg_digits, d, (a - d) * 60.0);
    return std::string(buf);
  };
  constexpr double kRad = M_PI / 180.0, kM = 6371000.0 * M_PI / 180.0;
  std::string out;
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const P &p = pts[i], &a = pts[i - 1], &b = pts[i + 1];
    const double dt = seconds_apart(b.t, a.t);
    if (dt <= 0.0) continue;
    const double vn = (b.lat - a.lat) * kM / dt,
                 ve = (b.lon - a.lon) * kM * std::cos(p.lat * kRad) / dt;
    const double sog = std::hypot(vn, ve),
                 cog = std::fmod(std::atan2(ve, vn) / kRad + 360.0, 360.0);
    // "2025-06-21T11:18:29Z" -> 111829.00 and 210625
    const std::string hms = p.t.substr(11, 2) + p.t.substr(14, 2) + p.t.substr(17, 2) + ".00";
    const std::string date = p.t.substr(8, 2) + p.t.substr(5, 2) + p.t.substr(2, 2);
    char speed[64];
    std::snprintf(speed, sizeof speed, "%.2f,%.1f", sog * 3600.0 / 1852.0, cog);
    out += sentence("GPRMC," + hms + ",A," + dm(p.lat, 2) + (p.lat < 0 ? ",S," : ",N,") +
                    dm(p.lon, 3) + (p.lon < 0 ? ",W," : ",E,") + speed + "," + date + ",,,A");
    const double tw = wind_from(seconds_apart(p.t, pts.front().t)) * kRad;
    const double rn = -6.0 * std::cos(tw) - vn, re = -6.0 * std::sin(tw) - ve;  // air past the boat
    const double awa = std::fmod(std::atan2(-re, -rn) / kRad - cog + 720.0, 360.0);
    char mwv[64];
    std::snprintf(mwv, sizeof mwv, "WIMWV,%.1f,R,%.2f,M,A", awa, std::hypot(rn, re));
    out += sentence(mwv);
  }
  return out;
}

// A boat with a wind instrument: its log's wind overrides the estimate from the tacks, and the
// report says how far that estimate was off. The first race's real track, with the apparent wind
// an instrument would read in a true wind from 110 deg (the sailor's note) swinging +-8 deg over
// 5 minutes: the session's wind is the instrument's (within 1 deg of its mean, 110), the estimate
// from the tacks is reported beside it (the figure of the GPX test above, within 8 deg), the
// error is their difference, the manoeuvres are the same tacks and gybes, and a coach's wind
// still overrides both.
TEST_F(ImportTest, AWindInstrumentInTheLogOverridesTheEstimateAndMeasuresIt) {
  const std::string csv =
      std::string(TELLTALE_TEST_DATA_DIR) + "/maxsail_valencia/ESP30782-P01.csv";
  const std::string log = instrument_nmea(
      csv, [](double t_s) { return 110.0 + 8.0 * std::sin(2.0 * M_PI * t_s / 300.0); });
  auto res = upload("boat=ESP30782-W&name=race1.nmea", log, kAnalyst);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const auto done = finished(nlohmann::json::parse(res->body)["id"].get<std::int64_t>());
  ASSERT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(done["format"], "nmea");
  ASSERT_EQ(done["sessions"].size(), 1u) << done.dump();
  // Every epoch has its wind, made true again from the apparent (the boat's velocity taken out).
  EXPECT_GT(done["wind_added"].get<int>(), 1900) << done.dump();
  EXPECT_EQ(done["wind_added"], done["points"]) << done.dump();
  const std::string base =
      "/api/v1/sessions/" + std::to_string(done["sessions"][0].get<std::int64_t>());
  const auto got = get_json(base + "/manoeuvres");
  const auto& w = got["wind"];
  ASSERT_EQ(w["source"], "instrument") << w.dump();
  EXPECT_TRUE(w["given"].get<bool>());
  EXPECT_NEAR(w["from_deg"].get<double>(), 110.0, 1.0) << w.dump();
  EXPECT_NEAR(w["instrument"]["from_deg"].get<double>(), 110.0, 1.0) << w.dump();
  EXPECT_NEAR(w["instrument"]["speed_m_s"].get<double>(), 6.0, 0.1) << w.dump();
  EXPECT_GT(w["instrument"]["spread_deg"].get<double>(), 3.0) << w.dump();  // the swing is seen
  EXPECT_LT(w["instrument"]["spread_deg"].get<double>(), 8.0) << w.dump();
  ASSERT_TRUE(w["estimated_from_deg"].is_number()) << w.dump();
  const double est = w["estimated_from_deg"].get<double>();
  EXPECT_LT(std::abs(std::remainder(est - 110.0, 360.0)), 8.0) << w.dump();
  EXPECT_NEAR(w["estimate_error_deg"].get<double>(),
              std::remainder(est - w["instrument"]["from_deg"].get<double>(), 360.0), 1e-9);
  int tacks = 0, gybes = 0;
  for (const auto& m : got["manoeuvres"]) {
    tacks += m["kind"] == "tack";
    gybes += m["kind"] == "gybe";
  }
  EXPECT_GE(tacks, 7) << got.dump();  // the race's 7 after the start, and any before it
  EXPECT_GE(gybes, 2) << got.dump();
  const auto coach = get_json(base + "/manoeuvres?wind_from_deg=100");
  EXPECT_EQ(coach["wind"]["source"], "coach") << coach["wind"].dump();
  EXPECT_EQ(coach["wind"]["from_deg"].get<double>(), 100.0);
  EXPECT_TRUE(coach["wind"]["instrument"].is_null()) << coach["wind"].dump();
}

}  // namespace
}  // namespace telltale::testing
