// The wire, read by another vendor: an Eclipse Cyclone DDS reader built from
// Cyclone's own idlc output for idl/telltale.idl must receive and decode every Telltale topic,
// written by the real Fast DDS binaries (boat_node: attitude, backfill, fix backfill, status;
// shore_server: receipts of both kinds, alarm rules, alarm events; wearable_node: wearable motion
// and status) and, for
// BoatFix, both the boat's simulated course and a Fast DDS writer in this test on the production
// profiles whose every value is known, which also writes the BoatWind of a wind instrument.
// Everything on a private domain on 127.0.0.1 (tests/interop/cyclone_loopback.xml).
#include <signal.h>

#include <cmath>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <map>
#include <set>
#include <sstream>

#include "dds_participant.hpp"
#include "shore_fixture.hpp"
#include "telltalePubSubTypes.h"

namespace telltale::testing {
namespace {

using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;

constexpr const char* kBoat = "ib1";
constexpr const char* kAthlete = "iw1";
// What the test's own BoatFix writer sends (as boat kFixBoat): the reader must print exactly these.
constexpr const char* kFixBoat = "ifix";
constexpr double kLat = 43.2951234;
constexpr double kLon = 5.3738765;
constexpr double kSog = 3.25;
constexpr double kCog = 123.5;
constexpr int kSatellites = 9;
constexpr float kHdop = 0.75f;
constexpr std::uint64_t kFixBoot = 4242;
// And its BoatWind beside each fix (a wind instrument on that boat).
constexpr double kWindFrom = 247.5;
constexpr double kWindSpeed = 6.25;

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// Fast DDS BoatFix and BoatWind writers (profile fix_writer of the production profiles file, as
/// the boat node's) at 10 Hz.
class FixPublisher {
 public:
  explicit FixPublisher(int domain) {
    dds::DdsOptions o;
    o.domain = domain;
    participant_ = std::make_unique<dds::Participant>(o, "interop_fix");
    writer_ = participant_->writer(
        participant_->topic(dds::kTopicBoatFix, fdds::TypeSupport(new msg::BoatFixPubSubType())),
        "fix_writer");
    wind_writer_ = participant_->writer(
        participant_->topic(dds::kTopicBoatWind, fdds::TypeSupport(new msg::BoatWindPubSubType())),
        "fix_writer");
    thread_ = std::thread([this] { run(); });
  }
  ~FixPublisher() {
    stop_ = true;
    thread_.join();
  }
  FixPublisher(const FixPublisher&) = delete;
  FixPublisher& operator=(const FixPublisher&) = delete;

 private:
  void run() {
    std::uint64_t seq = 0;
    while (!stop_) {
      msg::BoatFix m;
      m.boat_id(kFixBoat);
      m.seq(++seq);
      const auto t = now_ns();
      m.t_utc_ns(t);
      m.gnss_utc_ns(t - 200'000'000ULL);
      m.lat_deg(kLat);
      m.lon_deg(kLon);
      m.sog_m_s(kSog);
      m.cog_deg(kCog);
      m.fix(msg::FIX_KIND_3D);
      m.satellites(static_cast<std::uint8_t>(kSatellites));
      m.hdop(kHdop);
      m.boot_id(kFixBoot);
      writer_->write(&m);
      msg::BoatWind w;
      w.boat_id(kFixBoat);
      w.seq(seq);
      w.t_utc_ns(t);
      w.from_deg(kWindFrom);
      w.speed_m_s(kWindSpeed);
      w.source("mwv_apparent");
      w.boot_id(kFixBoot);
      wind_writer_->write(&w);
      std::this_thread::sleep_for(100ms);
    }
  }
  std::unique_ptr<dds::Participant> participant_;
  fdds::DataWriter* writer_ = nullptr;
  fdds::DataWriter* wind_writer_ = nullptr;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// One "sample topic=T k=v k=\"text\" ..." line of the reader.
struct Sample {
  std::string topic;
  std::map<std::string, std::string> f;
  [[nodiscard]] double num(const std::string& k) const {
    const auto it = f.find(k);
    return it == f.end() ? std::nan("") : std::strtod(it->second.c_str(), nullptr);
  }
  [[nodiscard]] std::uint64_t u64(const std::string& k) const {
    const auto it = f.find(k);
    return it == f.end() ? 0 : std::strtoull(it->second.c_str(), nullptr, 10);
  }
  [[nodiscard]] std::string str(const std::string& k) const {
    const auto it = f.find(k);
    return it == f.end() ? std::string("<missing>") : it->second;
  }
};

/// key=value pairs after `head`; values in double quotes may hold spaces (\" and \\ escaped).
std::map<std::string, std::string> parse_fields(const std::string& line, std::size_t from) {
  std::map<std::string, std::string> out;
  std::size_t i = from;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ') ++i;
    const auto eq = line.find('=', i);
    if (eq == std::string::npos) break;
    const std::string key = line.substr(i, eq - i);
    std::string value;
    i = eq + 1;
    if (i < line.size() && line[i] == '"') {
      for (++i; i < line.size() && line[i] != '"'; ++i) {
        if (line[i] == '\\' && i + 1 < line.size()) ++i;
        value += line[i];
      }
      ++i;
    } else {
      const auto sp = line.find(' ', i);
      value = line.substr(i, sp == std::string::npos ? std::string::npos : sp - i);
      i = sp == std::string::npos ? line.size() : sp;
    }
    out[key] = value;
  }
  return out;
}

std::vector<Sample> samples_of(const std::string& output) {
  std::vector<Sample> out;
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("sample ", 0) != 0) continue;
    Sample s;
    s.f = parse_fields(line, 7);
    s.topic = s.f["topic"];
    out.push_back(std::move(s));
  }
  return out;
}

/// Samples each topic must deliver: a second of live data, a run's backfill, a few receipts and
/// statuses, the one rule and at least one event.
const std::map<std::string, long> kMinimum = {
    {"telltale_boat_attitude", 50},     {"telltale_boat_backfill", 20},
    {"telltale_shore_ack", 3},          {"telltale_node_status", 3},
    {"telltale_alarm_rules", 1},        {"telltale_alarm_events", 1},
    {"telltale_wearable_motion", 3},    {"telltale_boat_fix", 10},
    {"telltale_boat_fix_backfill", 10}, {"telltale_shore_fix_ack", 3},
    {"telltale_boat_wind", 10}};

/// A count of the reader's "counts" line; -1 when the topic is missing.
long count_of(const std::map<std::string, std::string>& counts, const std::string& topic) {
  const auto it = counts.find(topic);
  return it == counts.end() || it->second.empty() ? -1
                                                  : std::strtol(it->second.c_str(), nullptr, 10);
}

bool enough(const std::map<std::string, std::string>& counts) {
  for (const auto& [topic, n] : kMinimum)
    if (count_of(counts, topic) < n) return false;
  return true;
}

/// The reader's lines other than samples and counts: ready, matched, incompatible.
std::string discovery_lines(const std::string& output) {
  std::string out;
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("sample ", 0) != 0 && line.rfind("counts ", 0) != 0) out += line + "\n";
  return out;
}

class InteropTest : public ShoreFixture {
 protected:
  // The shore starts in the test, after the boat: the boat then has a run the shore lacks, and
  // backfills it.
  void SetUp() override {
    dir_ = make_temp_dir();
    domain_ = unique_domain();
  }
};

TEST_F(InteropTest, CycloneReaderDecodesEveryTopic) {
  const std::string domain = std::to_string(domain_);
  Process reader({TELLTALE_CYCLONE_READER, "--domain", domain, "--print", "-1"},
                 {std::string("CYCLONEDDS_URI=file://") + TELLTALE_CYCLONE_CONFIG});
  ASSERT_TRUE(reader.wait_for_line("cyclone_reader ready: ", 20s)) << reader.output();

  Process& boat = start_boat(kBoat, {"--group", "ILCA7"});
  std::smatch m;
  const std::string boat_out = boat.output();
  ASSERT_TRUE(std::regex_search(boat_out, m, std::regex(R"(boot=([0-9a-f]{16}))"))) << boat_out;
  const std::uint64_t boot = std::stoull(m[1], nullptr, 16);
  std::this_thread::sleep_for(4s);  // ~100 samples and ~40 fixes the shore will lack: backfill

  start_shore();
  auto c = client();
  auto put = c.Put("/api/v1/alarms/rules", bearer(),
                   R"([{"id":"flat","quantity":"heel","min_deg":-2,"max_deg":2,"hold_s":0.2,
                        "hysteresis_deg":0.5,"level":"alarm"}])",
                   "application/json");
  ASSERT_TRUE(put);
  ASSERT_EQ(put->status, 200) << put->body;
  Process walker({bin_dir() + "/wearable_node", "--domain", domain, "--athlete-id", kAthlete});
  ASSERT_TRUE(walker.wait_for_line("wearable_node ready: ", 20s)) << walker.output();
  FixPublisher fix(domain_);

  std::map<std::string, std::string> counts;
  const auto deadline = std::chrono::steady_clock::now() + 45s;
  while (!enough(counts) && std::chrono::steady_clock::now() < deadline) {
    const auto line = reader.wait_for_line("counts ", 2s);
    if (line) counts = parse_fields(*line, 7);
  }
  ASSERT_EQ(reader.stop(SIGINT), 0) << reader.output();
  const auto stopped = reader.wait_for_line("cyclone_reader stopped: ", 1s);
  ASSERT_TRUE(stopped) << reader.output();
  counts = parse_fields(*stopped, 24);
  std::cout << "[ counts   ] " << stopped->substr(24) << "\n";
  for (const auto& [topic, n] : kMinimum)
    EXPECT_GE(count_of(counts, topic), n) << topic << ": the Cyclone reader got too few samples";
  if (!enough(counts))
    ADD_FAILURE() << "the Cyclone reader's discovery:\n" << discovery_lines(reader.output());

  // Every printed sample decodes to the values its writer put in.
  const auto samples = samples_of(reader.output());
  std::map<std::string, int> seen;
  const std::uint64_t now = now_ns();
  const auto plausible_time = [&](std::uint64_t t) {
    return t > now - 3600ULL * 1000000000ULL && t < now + 60ULL * 1000000000ULL;
  };
  for (const auto& s : samples) {
    ++seen[s.topic];
    SCOPED_TRACE(s.topic);
    if (s.topic == "telltale_boat_attitude" || s.topic == "telltale_boat_backfill") {
      EXPECT_EQ(s.str("boat_id"), kBoat);
      EXPECT_GE(s.u64("seq"), 1U);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns"))) << s.u64("t_utc_ns");
      EXPECT_GE(s.num("heel_deg"), -90.0);
      EXPECT_LE(s.num("heel_deg"), 90.0);
      EXPECT_GE(s.num("pitch_deg"), -90.0);
      EXPECT_LE(s.num("pitch_deg"), 90.0);
      const double heading = s.num("heading_deg");
      EXPECT_TRUE(std::isnan(heading) || (heading >= 0.0 && heading <= 360.0)) << heading;
      EXPECT_GE(s.num("quality"), 0.0);
      EXPECT_LE(s.num("quality"), 1.0);
      EXPECT_EQ(s.str("led_count"), "6");  // the nested LedPanel: the boat's default panel
      EXPECT_EQ(s.u64("boot_id"), boot);   // the last member: nothing shifted on the way
    } else if (s.topic == "telltale_shore_ack") {
      EXPECT_EQ(s.str("boat_id"), kBoat);
      EXPECT_EQ(s.u64("boot_id"), boot);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
    } else if (s.topic == "telltale_shore_fix_ack") {
      // The boat's fixes and the test writer's are both recorded, so both get receipts.
      if (s.str("boat_id") == kBoat) {
        EXPECT_EQ(s.u64("boot_id"), boot);
      } else {
        EXPECT_EQ(s.str("boat_id"), kFixBoat);
        EXPECT_EQ(s.u64("boot_id"), kFixBoot);
      }
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
    } else if (s.topic == "telltale_boat_fix_backfill") {
      // The boat's fixes from before the shore started, from its log: every member as sent.
      EXPECT_EQ(s.str("boat_id"), kBoat);
      EXPECT_EQ(s.u64("boot_id"), boot);
      EXPECT_GE(s.u64("seq"), 1U);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      const int kind = std::stoi(s.str("fix"));
      EXPECT_TRUE(kind >= 0 && kind <= 3) << kind;
      if (kind > 0) {
        EXPECT_GE(s.num("lat_deg"), -90.0);
        EXPECT_LE(s.num("lat_deg"), 90.0);
        EXPECT_GE(s.num("lon_deg"), -180.0);
        EXPECT_LE(s.num("lon_deg"), 180.0);
        EXPECT_GE(s.num("sog_m_s"), 0.0);
      }
    } else if (s.topic == "telltale_node_status") {
      EXPECT_TRUE(s.str("node_id") == kBoat || s.str("node_id") == kAthlete || s.str("kind") == "2")
          << s.str("node_id");
      EXPECT_FALSE(s.str("software_version").empty());
      EXPECT_GE(s.num("uptime_s"), 0.0);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      if (s.str("node_id") == kBoat) {
        EXPECT_EQ(s.str("kind"), "0");
        EXPECT_EQ(s.str("group"), "ILCA7");
      }
    } else if (s.topic == "telltale_alarm_rules") {
      EXPECT_EQ(s.str("rule_id"), "flat");
      EXPECT_EQ(s.str("quantity"), "0");
      EXPECT_DOUBLE_EQ(s.num("min_deg"), -2.0);
      EXPECT_DOUBLE_EQ(s.num("max_deg"), 2.0);
      EXPECT_DOUBLE_EQ(s.num("hold_s"), 0.2);
      EXPECT_DOUBLE_EQ(s.num("hysteresis_deg"), 0.5);
      EXPECT_EQ(s.str("level"), "2");
      EXPECT_EQ(s.str("enabled"), "1");
      EXPECT_GE(s.u64("revision"), 1U);
    } else if (s.topic == "telltale_alarm_events") {
      EXPECT_EQ(s.str("boat_id"), kBoat);
      EXPECT_EQ(s.str("rule_id"), "flat");
      EXPECT_EQ(s.str("level"), "2");
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      if (s.str("phase") == "0") {
        EXPECT_GT(std::abs(s.num("value_deg")), 2.0);
      }
    } else if (s.topic == "telltale_wearable_motion") {
      EXPECT_EQ(s.str("athlete_id"), kAthlete);
      EXPECT_GE(s.u64("seq"), 1U);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      EXPECT_LE(std::stoi(s.str("gait")), 6);
      EXPECT_LE(std::stoi(s.str("pose")), 5);
    } else if (s.topic == "telltale_boat_fix" && s.str("boat_id") == kBoat) {
      ++seen["fix from the boat"];  // its simulated course
      EXPECT_EQ(s.u64("boot_id"), boot);
      EXPECT_GE(s.u64("seq"), 1U);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      const int kind = std::stoi(s.str("fix"));
      EXPECT_TRUE(kind >= 0 && kind <= 3) << kind;
      if (kind > 0) {
        EXPECT_GE(s.num("lat_deg"), -90.0);
        EXPECT_LE(s.num("lat_deg"), 90.0);
        EXPECT_GE(s.num("lon_deg"), -180.0);
        EXPECT_LE(s.num("lon_deg"), 180.0);
        EXPECT_GE(s.num("sog_m_s"), 0.0);
      }
    } else if (s.topic == "telltale_boat_fix") {
      ++seen["fix from the test"];
      EXPECT_EQ(s.str("boat_id"), kFixBoat);
      EXPECT_NEAR(s.num("lat_deg"), kLat, 1e-9);
      EXPECT_NEAR(s.num("lon_deg"), kLon, 1e-9);
      EXPECT_DOUBLE_EQ(s.num("sog_m_s"), kSog);
      EXPECT_DOUBLE_EQ(s.num("cog_deg"), kCog);
      EXPECT_EQ(s.str("fix"), "2");  // FIX_KIND_3D
      EXPECT_EQ(s.str("satellites"), std::to_string(kSatellites));
      EXPECT_DOUBLE_EQ(s.num("hdop"), static_cast<double>(kHdop));
      EXPECT_EQ(s.u64("boot_id"), kFixBoot);
      EXPECT_EQ(s.u64("t_utc_ns") - s.u64("gnss_utc_ns"), 200'000'000ULL);
    } else if (s.topic == "telltale_boat_wind") {
      EXPECT_EQ(s.str("boat_id"), kFixBoat);
      EXPECT_GE(s.u64("seq"), 1U);
      EXPECT_TRUE(plausible_time(s.u64("t_utc_ns")));
      EXPECT_DOUBLE_EQ(s.num("from_deg"), kWindFrom);
      EXPECT_DOUBLE_EQ(s.num("speed_m_s"), kWindSpeed);
      EXPECT_EQ(s.str("source"), "mwv_apparent");
      EXPECT_EQ(s.u64("boot_id"), kFixBoot);
    } else {
      ADD_FAILURE() << "unknown topic " << s.topic;
    }
  }
  for (const auto& [topic, n] : kMinimum) EXPECT_GE(seen[topic], n) << topic << " too few printed";
  EXPECT_GE(seen["fix from the boat"], 5);
  EXPECT_GE(seen["fix from the test"], 5);
  EXPECT_EQ(reader.output().find("incompatible "), std::string::npos)
      << discovery_lines(reader.output());
}

}  // namespace
}  // namespace telltale::testing
