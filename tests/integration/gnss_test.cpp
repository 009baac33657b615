// GNSS end to end: NMEA 0183 on a pseudo-terminal and on loopback UDP, and a real gpsd fed by a
// pseudo-terminal, bring a boat's position to GET /api/v1/boats; malformed sentences and jumps
// are counted on the boat and never shown; a session's GPX is read back by gpsbabel.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pty.h>
#include <signal.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <ctime>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "../unit/nmea_sentence.hpp"
#include "shore_fixture.hpp"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

constexpr double kLat0 = 54.3440, kLon0 = 10.1900;  // Kiel outer fjord
constexpr double kNorthSpeed = 3.0;                 // m/s
constexpr double kMPerDegLat = 111195.0;

using telltale::test::nmea;

std::string ddmm(double deg, bool lat) {
  const double a = std::abs(deg);
  const int d = static_cast<int>(a);
  char buf[32];
  std::snprintf(buf, sizeof buf, lat ? "%02d%07.4f,%c" : "%03d%07.4f,%c", d, (a - d) * 60.0,
                lat ? (deg >= 0 ? 'N' : 'S') : (deg >= 0 ? 'E' : 'W'));
  return buf;
}

/// One receiver epoch (RMC + GGA + GSA) `north_m` north of the start, now.
std::string epoch(double north_m, double lon_deg = kLon0) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t secs = std::chrono::system_clock::to_time_t(now);
  const int centis = static_cast<int>(
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000 /
      10);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char hms[32], date[32];
  std::snprintf(hms, sizeof hms, "%02d%02d%02d.%02d", tm.tm_hour, tm.tm_min, tm.tm_sec, centis);
  std::snprintf(date, sizeof date, "%02d%02d%02d", tm.tm_mday, tm.tm_mon + 1, tm.tm_year % 100);
  const double lat = kLat0 + north_m / kMPerDegLat;
  const std::string pos = ddmm(lat, true) + "," + ddmm(lon_deg, false);
  char sog[16];
  std::snprintf(sog, sizeof sog, "%.2f", kNorthSpeed / 0.514444);
  return nmea("GNRMC," + std::string(hms) + ",A," + pos + "," + sog + ",0.0," + date + ",,,A") +
         nmea("GNGGA," + std::string(hms) + "," + pos + ",1,10,0.8,5.0,M,40.0,M,,") +
         nmea("GNGSA,A,3,01,02,03,04,05,06,07,08,09,10,,,1.4,0.8,1.1");
}

/// Writes epochs every 200 ms through `write` until stopped; between them, on schedule, a
/// garbage line, a bad checksum and one jump of 2 km east.
class Feeder {
 public:
  explicit Feeder(std::function<void(const std::string&)> write) : write_(std::move(write)) {
    thread_ = std::thread([this] {
      for (int k = 0; !stop_; ++k) {
        const double north = kNorthSpeed * 0.2 * k;
        std::string out = epoch(north);
        if (k == 15) out = "\x01\x02 line noise $GPRMC,garbage\r\n" + out;
        if (k == 20) out = "$GNRMC,120000.00,A,5420.640,N,01011.400,E,5.0,045.0,021226,,,A*00\r\n" + out;
        if (k == 25) out = epoch(north, kLon0 + 2000.0 / (kMPerDegLat * std::cos(kLat0 * M_PI / 180)));
        write_(out);
        sent_north_ = north;
        std::this_thread::sleep_for(200ms);
      }
    });
  }
  ~Feeder() {
    stop_ = true;
    thread_.join();
  }
  double last_north_m() const { return sent_north_; }

 private:
  std::function<void(const std::string&)> write_;
  std::atomic<bool> stop_{false};
  std::atomic<double> sent_north_{0.0};
  std::thread thread_;
};

struct Pty {
  int master = -1, slave = -1;
  std::string name;
  Pty() {
    char buf[256];
    if (openpty(&master, &slave, buf, nullptr, nullptr) != 0) return;
    name = buf;
    termios raw{};
    tcgetattr(slave, &raw);
    cfmakeraw(&raw);
    tcsetattr(slave, TCSANOW, &raw);
  }
  ~Pty() {
    if (master >= 0) ::close(master);
    if (slave >= 0) ::close(slave);
  }
};

class GnssTest : public ShoreFixture {
 protected:
  /// Polls GET /boats until the boat has a position, recording every position seen; checks the
  /// positions follow the line north (never the 2 km jump), then the boat's own counts.
  void expect_track_followed(const std::string& boat, const Feeder& feed, bool expect_counts) {
    std::vector<std::pair<double, double>> seen;
    json last;
    const bool positioned = eventually(
        [&] {
          auto boats = boats_by_id();
          if (!boats.count(boat)) return false;
          last = boats[boat];
          if (last["lat_deg"].is_number())
            seen.emplace_back(last["lat_deg"].get<double>(), last["lon_deg"].get<double>());
          // Past the jump (epoch 25 at 5 Hz), and its status has been published since.
          return feed.last_north_m() > kNorthSpeed * 0.2 * 32 && seen.size() > 10;
        },
        30s);
    ASSERT_TRUE(positioned) << last.dump() << "\n" << boats_.back()->output();
    for (const auto& [lat, lon] : seen) {
      EXPECT_NEAR(lon, kLon0, 1e-6) << "a position off the line was shown: " << lat << "," << lon;
      const double north = (lat - kLat0) * kMPerDegLat;
      EXPECT_GE(north, -1.0);
      EXPECT_LE(north, feed.last_north_m() + 1.0);
    }
    EXPECT_EQ(last["gnss_fix"], "3d");
    EXPECT_NEAR(last["sog_m_s"].get<double>(), kNorthSpeed, 0.01);
    // gpsd reports satellites in its SKY report, which needs GSV sentences: NMEA straight only.
    if (expect_counts) {
      EXPECT_EQ(last["gnss"]["satellites"], 10);
    }
    EXPECT_TRUE(last["gnss"]["clock_offset_ms"].is_number()) << last.dump();
    // The stored track holds no point off the line either.
    const json track = get_json("/api/v1/boats/" + boat + "/track");
    ASSERT_TRUE(track.is_object());
    EXPECT_GT(track["points"].get<int>(), 10);
    for (const auto& lon : track["lon_deg"]) EXPECT_NEAR(lon.get<double>(), kLon0, 1e-6);
    if (!expect_counts) return;
    // The boat counted what it refused (its status, shown in GET /boats).
    EXPECT_TRUE(eventually(
        [&] {
          const auto text = boats_by_id()[boat]["status"]["health_text"];
          return text.is_string() &&
                 text.get<std::string>().find("gnss jumps 1") != std::string::npos &&
                 text.get<std::string>().find("gnss bad lines 2") != std::string::npos;
        },
        5s))
        << boats_by_id()[boat].dump();
  }
};

TEST_F(GnssTest, NmeaOnAPtyBringsThePositionJumpsAndGarbageCountedNeverShown) {
  Pty pty;
  ASSERT_FALSE(pty.name.empty());
  start_boat("gnss_pty", {"--gnss", "nmea:" + pty.name + "@38400"});
  Feeder feed([&](const std::string& s) { (void)::write(pty.master, s.data(), s.size()); });
  expect_track_followed("gnss_pty", feed, true);
}

TEST_F(GnssTest, NmeaOverUdpBringsThePosition) {
  const int port = free_loopback_port(SOCK_DGRAM);
  start_boat("gnss_udp", {"--gnss", "nmea:udp:" + std::to_string(port)});
  const int tx = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  Feeder feed([&](const std::string& s) {
    (void)::sendto(tx, s.data(), s.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  });
  expect_track_followed("gnss_udp", feed, true);
  ::close(tx);
}

// A wind instrument on the same NMEA line (a multiplexer's output): the boat reads its MWV,
// makes the apparent wind true with its own course and speed, and publishes it; the shore records
// it and the session's manoeuvres take their wind from it. Apparent 10 m/s from 45 deg off the bow
// on a boat sailing north at 3 m/s (no heading source: the COG, 0, turns it): the air moves past
// at -10 m/s along 45 deg, plus the boat's 3 m/s north leaves the air moving (-4.07 north, -7.07
// east) over the ground: a true wind of 8.16 m/s from 60.1 deg.
TEST_F(GnssTest, AWindInstrumentOnTheNmeaLineIsRecordedAsTheTrueWind) {
  const int port = free_loopback_port(SOCK_DGRAM);
  start_boat("gnss_wind", {"--gnss", "nmea:udp:" + std::to_string(port)});
  const int tx = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::atomic<bool> stop{false};
  std::thread feeder([&] {
    for (int k = 0; !stop; ++k) {
      const std::string out = epoch(kNorthSpeed * 0.2 * k) + nmea("WIMWV,045.0,R,10.0,M,A") +
                              nmea("WIMWV,045.0,R,10.0,M,V");  // status V: not a reading
      (void)::sendto(tx, out.data(), out.size(), 0, reinterpret_cast<const sockaddr*>(&to),
                     sizeof to);
      std::this_thread::sleep_for(200ms);
    }
  });
  const double wn = -10.0 * std::cos(M_PI / 4) + kNorthSpeed, we = -10.0 * std::sin(M_PI / 4);
  const double expect_from = std::atan2(-we, -wn) * 180.0 / M_PI, expect_speed = std::hypot(wn, we);
  json wind;
  const bool recorded = eventually(
      [&] {
        const json sessions = get_json("/api/v1/sessions?boat=gnss_wind");
        if (!sessions.is_array() || sessions.empty()) return false;
        wind =
            get_json("/api/v1/sessions/" + std::to_string(sessions[0]["id"].get<std::int64_t>()) +
                     "/manoeuvres")["wind"];
        return wind["instrument"].is_object() && wind["instrument"]["readings"].get<int>() >= 20;
      },
      30s);
  stop = true;
  feeder.join();
  ::close(tx);
  ASSERT_TRUE(recorded) << wind.dump() << "\n" << boats_.back()->output();
  EXPECT_EQ(wind["source"], "instrument");
  EXPECT_NEAR(wind["instrument"]["from_deg"].get<double>(), expect_from, 0.5) << wind.dump();
  EXPECT_NEAR(wind["instrument"]["speed_m_s"].get<double>(), expect_speed, 0.05) << wind.dump();
  EXPECT_LT(wind["instrument"]["spread_deg"].get<double>(), 0.5) << wind.dump();
}

std::string find_program(const std::string& name) {
  for (const char* dir : {"/usr/sbin", "/usr/bin", "/usr/local/sbin", "/usr/local/bin"}) {
    const std::string p = std::string(dir) + "/" + name;
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

TEST_F(GnssTest, ARealGpsdFedByAPtyBringsThePosition) {
  const std::string gpsd = find_program("gpsd");
  ASSERT_FALSE(gpsd.empty()) << "gpsd is not installed (deploy/packages.txt lists it)";
  Pty pty;
  ASSERT_FALSE(pty.name.empty());
  const int port = free_loopback_port(SOCK_STREAM);
  // -N foreground, -n poll the device without waiting for a client, -S our port; gpsd listens on
  // loopback only unless -G is given. Its control socket goes in the test's folder.
  Process gpsd_proc({gpsd, "-N", "-n", "-S", std::to_string(port), "-F", dir_ + "/gpsd.sock",
                     pty.name});
  Feeder feed([&](const std::string& s) { (void)::write(pty.master, s.data(), s.size()); });
  start_boat("gnss_gpsd", {"--gnss", "gpsd:127.0.0.1:" + std::to_string(port)});
  // gpsd decodes the sentences itself: the garbage never reaches the boat, and gpsd passes the
  // jump on, which the boat's gate refuses.
  expect_track_followed("gnss_gpsd", feed, false);
  EXPECT_TRUE(eventually(
      [&] {
        const auto text = boats_by_id()["gnss_gpsd"]["status"]["health_text"];
        return text.is_string() && text.get<std::string>().find("gnss jumps 1") != std::string::npos;
      },
      5s))
      << boats_by_id()["gnss_gpsd"].dump();
}

TEST_F(GnssTest, NoFixShowsNullNeverAStalePosition) {
  Pty pty;
  ASSERT_FALSE(pty.name.empty());
  start_boat("gnss_nofix", {"--gnss", "nmea:" + pty.name + "@38400"});
  std::atomic<bool> stop{false};
  std::thread feeder([&] {
    while (!stop) {
      const std::string s = nmea("GPRMC,120000.00,V,,,,,,,021226,,,N") +
                            nmea("GPGGA,120000.00,,,,,0,00,,,M,,M,,");
      (void)::write(pty.master, s.data(), s.size());
      std::this_thread::sleep_for(200ms);
    }
  });
  json b;
  const bool seen = eventually(
      [&] {
        b = boats_by_id()["gnss_nofix"];
        return b.is_object() && b["gnss_fix"] == "none";
      },
      20s);
  stop = true;
  feeder.join();
  ASSERT_TRUE(seen) << b.dump();
  EXPECT_TRUE(b["lat_deg"].is_null() && b["lon_deg"].is_null() && b["sog_m_s"].is_null());
}

TEST_F(GnssTest, SessionGpxIsReadBackByGpsbabelWithEveryPoint) {
  const std::string gpsbabel = find_program("gpsbabel");
  ASSERT_FALSE(gpsbabel.empty()) << "gpsbabel is not installed (deploy/packages.txt lists it)";
  Process& boat = start_boat("gpx1");  // --source sim: the simulated race course
  ASSERT_TRUE(eventually(
      [&] {
        const auto s = get_json("/api/v1/sessions?boat=gpx1");
        return s.is_array() && !s.empty() && s[0]["duration_s"].get<double>() > 6.0;
      },
      30s));
  EXPECT_EQ(boat.stop(SIGINT, 20s), 0) << boat.output();
  std::this_thread::sleep_for(1s);  // the last batch committed
  const json sessions = get_json("/api/v1/sessions?boat=gpx1");
  ASSERT_EQ(sessions.size(), 1u);
  const int id = sessions[0]["id"].get<int>();
  const json detail = get_json("/api/v1/sessions/" + std::to_string(id));
  const int fixes = detail["gnss"]["fixes"].get<int>();
  EXPECT_GT(fixes, 50) << "10 Hz for more than 6 s";
  EXPECT_GT(detail["gnss"]["distance_m"].get<double>(), 1.0);

  auto c = client();
  auto res = c.Get("/api/v1/sessions/" + std::to_string(id) + "/gpx", bearer());
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  const std::string gpx = dir_ + "/s.gpx", csv = dir_ + "/s.csv";
  std::ofstream(gpx) << res->body;
  Process babel({gpsbabel, "-t", "-i", "gpx", "-f", gpx, "-o", "unicsv", "-F", csv});
  EXPECT_EQ(babel.stop(0, 20s), 0) << babel.output();  // signal 0: just wait for it
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("No,Latitude,Longitude", 0), 0u) << line;
  int points = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string no, lat, lon;
    std::getline(ss, no, ',');
    std::getline(ss, lat, ',');
    std::getline(ss, lon, ',');
    EXPECT_NEAR(std::stod(lat), 54.344, 0.02) << line;
    EXPECT_NEAR(std::stod(lon), 10.19, 0.03) << line;
    ++points;
  }
  // Every fix of the session, none lost on the way out (the session's span may end a fix
  // before the last one stored).
  EXPECT_EQ(points, fixes) << res->body.substr(0, 800);
}

}  // namespace
}  // namespace telltale::testing
