// boat_node: runs the fusion core on a boat's sensors and publishes heel, pitch and heading over
// DDS; logs every published sample and GNSS fix to disk and backfills the shore after a link
// outage.
#include <arpa/inet.h>
#include <fastdds/rtps/transport/test_UDPv4TransportDescriptor.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fstream>
#include <functional>
#include <future>
#include <limits>
#include <random>
#include <regex>
#include <string>

#include "backfill.hpp"
#include "boat_dds.hpp"
#include "boat_wire.hpp"
#include "calibration_store.hpp"
#include "console.hpp"
#include "course_sim.hpp"
#include "csv.hpp"
#include "dds_cli.hpp"
#include "gnss_input.hpp"
#include "heading_input.hpp"
#include "imu_source.hpp"
#include "run_clock.hpp"
#include "session_log.hpp"
#include "shutdown.hpp"
#include "telltale/fusion/alarm_engine.hpp"
#include "telltale/fusion/attitude_speed.hpp"
#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/led_panel.hpp"
#include "telltale/fusion/mounting.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using telltale::fusion::AlarmLevel;
constexpr double kRadToDeg = 180.0 / M_PI;

struct Options {
  telltale::dds::DdsOptions dds;
  std::string boat_id;
  std::string group;
  std::string source = "sim";
  std::vector<std::string> headings;
  std::string gnss;
  double variation_deg = std::numeric_limits<double>::quiet_NaN();
  double rate_hz = 25.0;
  double imu_rate_hz = 100.0;
  std::uint64_t seed = 0;
  telltale::boat::ReplayOptions replay;
  std::string log_dir = "boat_log";
  int deliver_earlier_days = 7;
  double log_max_mb = 1024;
  std::string axis_remap = "x=x,y=y,z=z";
  std::string mount_file;
  /// Where the attitude filter's learnt sensor calibration is kept across restarts (empty:
  /// LOG_DIR/BOAT_ID.imu-calibration.json; "none": not kept).
  std::string calibration_file;
  /// The sensor's position from the boat's centre, boat axes (m): the filter's lever_arm_m.
  std::vector<double> sensor_offset_m{0.0, 0.0, 0.0};
  double calibrate_s = 0;
  bool console = false;
  std::string warn_command;
  double led_step_deg = 5.0;
  int leds_per_bar = 6;
  double default_max_heel_deg = 30.0;
  double gyro_range_dps = 250.0;  ///< L3G4200D default, as in the paper's instrument
  double acc_range_g = 2.0;       ///< LSM303DLH default
  std::string fault_drop_link;    ///< "START_S:DURATION_S"
};

/// Fault injection for tests: every packet this node sends is dropped from START_S to
/// START_S + DURATION_S after start (Fast DDS's test UDP transport, loopback only), as if the
/// radio link were cut.
void inject_link_drop(Options& o) {
  if (o.fault_drop_link.empty()) return;
  const auto colon = o.fault_drop_link.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument("--fault-drop-link takes START_S:DURATION_S");
  const double start_s = std::stod(o.fault_drop_link.substr(0, colon));
  const double duration_s = std::stod(o.fault_drop_link.substr(colon + 1));
  const auto t0 = Clock::now();
  o.dds.customize = [=](eprosima::fastdds::dds::DomainParticipantQos& qos) {
    auto lossy = std::make_shared<eprosima::fastdds::rtps::test_UDPv4TransportDescriptor>();
    lossy->interfaceWhiteList.push_back("127.0.0.1");
    lossy->maxInitialPeersRange = 40;
    lossy->messages_filter_ = [=](eprosima::fastrtps::rtps::CDRMessage_t&) {
      const double t = std::chrono::duration<double>(Clock::now() - t0).count();
      return t >= start_s && t < start_s + duration_s;
    };
    qos.transport().user_transports.clear();
    qos.transport().user_transports.push_back(lossy);
    qos.transport().use_builtin_transports = false;
  };
}

/// The host's IPv4 addresses on interfaces that are up (loopback excluded), sorted: when this
/// changes (a new DHCP lease, another radio) the node rejoins the DDS domain.
std::string local_addresses() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return {};
  std::vector<std::string> out;
  for (const ifaddrs* a = list; a; a = a->ifa_next) {
    if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET || (a->ifa_flags & IFF_LOOPBACK) ||
        !(a->ifa_flags & IFF_UP))
      continue;
    sockaddr_in in{};
    std::memcpy(&in, a->ifa_addr, sizeof in);
    char text[INET_ADDRSTRLEN] = {};
    inet_ntop(AF_INET, &in.sin_addr, text, sizeof text);
    out.emplace_back(text);
  }
  freeifaddrs(list);
  std::sort(out.begin(), out.end());
  std::string joined;
  for (const auto& s : out) joined += s + " ";
  return joined;
}

const std::regex kId("[A-Za-z0-9_-]{1,32}");

/// The rule a boat uses until a shore pushes its own: heel beyond +-N deg for 2 s.
std::vector<telltale::fusion::AlarmRule> default_rules(const Options& o) {
  telltale::fusion::AlarmRule r;
  r.id = "local-heel";
  r.quantity = telltale::fusion::AlarmQuantity::kHeel;
  r.min_deg = -o.default_max_heel_deg;
  r.max_deg = o.default_max_heel_deg;
  r.hold_s = 2.0;
  r.hysteresis_deg = 2.0;
  r.level = AlarmLevel::kAlarm;
  return {r};
}

/// Mounting offsets file: "heel_offset_deg pitch_offset_deg" on one line.
void load_offsets(const std::string& path, telltale::fusion::Mounting& m) {
  if (path.empty()) return;
  std::ifstream in(path);
  if (!in) return;  // not calibrated yet
  if (!(in >> m.heel_offset_deg >> m.pitch_offset_deg) || !std::isfinite(m.heel_offset_deg) ||
      !std::isfinite(m.pitch_offset_deg) || std::abs(m.heel_offset_deg) > 45 ||
      std::abs(m.pitch_offset_deg) > 45)
    throw std::invalid_argument("mount file " + path + ": expected two offsets in degrees");
}

void save_offsets(const std::string& path, const telltale::fusion::Mounting& m) {
  std::ofstream out(path + ".tmp");
  out << m.heel_offset_deg << ' ' << m.pitch_offset_deg << '\n';
  out.close();
  if (!out || std::rename((path + ".tmp").c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot write mount file " + path);
}

double unix_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// What a calibration is the calibration of: the IMU source, the simulator's seed (each seed is
/// another simulated sensor), the axis remap (the filter's body axes) and the ranges.
std::string sensor_identity(const Options& o, const std::string& source, std::uint64_t seed) {
  std::string id = source;
  if (source.rfind("sim", 0) == 0) id += " seed=" + std::to_string(seed);
  char ranges[96];
  std::snprintf(ranges, sizeof ranges, " gyro=%gdps acc=%gg", o.gyro_range_dps, o.acc_range_g);
  return id + " remap=" + o.axis_remap + ranges;
}

void run(const Options& o, telltale::ShutdownSignal& shutdown) {
  if (!std::regex_match(o.boat_id, kId))
    throw std::invalid_argument("boat id must be 1-32 of [A-Za-z0-9_-], got '" + o.boat_id + "'");
  if (!o.group.empty() && !std::regex_match(o.group, kId))
    throw std::invalid_argument("group must be 1-32 of [A-Za-z0-9_-], got '" + o.group + "'");
  if (!(o.rate_hz > 0.0 && o.rate_hz <= 200.0))
    throw std::invalid_argument("--rate-hz must be in (0, 200]");
  if (!(o.imu_rate_hz > 0.0 && o.imu_rate_hz <= 1000.0))
    throw std::invalid_argument("--imu-rate-hz must be in (0, 1000]");
  telltale::fusion::Mounting mounting;
  const auto remap = telltale::fusion::parse_axis_remap(o.axis_remap);
  if (!remap) throw std::invalid_argument("--axis-remap: e.g. x=-y,y=x,z=z (a proper rotation)");
  mounting.remap = *remap;
  load_offsets(o.mount_file, mounting);
  if (o.calibrate_s > 0 && o.mount_file.empty())
    throw std::invalid_argument("--calibrate-s needs --mount-file to store the offsets");

  const std::uint64_t seed = o.seed ? o.seed : std::hash<std::string>{}(o.boat_id);
  // --source sim: the IMU's race scenario and the simulated receiver sail one course (one seed,
  // one RaceCourse), so the attitude and the fixes are one boat's.
  std::shared_ptr<telltale::fusion::sim::RaceCourse> race;
  if (telltale::boat::is_race_source(o.source))
    race = std::make_shared<telltale::fusion::sim::RaceCourse>(seed);
  auto source = telltale::boat::make_imu_source(
      o.source, seed, o.imu_rate_hz, o.replay, [&] { return shutdown.stop_requested(); }, race);
  // Every record of this run is stamped on one clock (run_clock.hpp says why).
  const telltale::boat::RunClock run_clock;
  // GNSS: an explicit --gnss receiver, else the simulated race course with --source sim.
  std::unique_ptr<telltale::boat::GnssInput> gnss;
  if (!o.gnss.empty()) gnss = std::make_unique<telltale::boat::GnssInput>(o.gnss, run_clock);
  std::unique_ptr<telltale::boat::CourseSim> course;
  telltale::boat::GnssGate course_gate;
  if (!gnss && o.source.rfind("sim", 0) == 0)
    course = race ? std::make_unique<telltale::boat::CourseSim>(race)
                  : std::make_unique<telltale::boat::CourseSim>(seed);
  // Another scenario's IMU (sim:dinghy...) is not the course's boat: its fixes are published,
  // never fed to the attitude filter.
  const bool course_is_imu_boat = course && race;
  std::unique_ptr<telltale::boat::HeadingInput> heading;
  if (!o.headings.empty())
    heading = std::make_unique<telltale::boat::HeadingInput>(o.headings, o.variation_deg);

  std::random_device rd;
  const std::uint64_t boot_id =
      (static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ static_cast<std::uint64_t>(getpid());
  telltale::boat::SessionLog log({o.log_dir, o.boat_id, boot_id, 100000,
                                  static_cast<std::uint64_t>(o.log_max_mb * 1024 * 1024)});
  // The fixes beside it, in the same directory under the same budget (session_log.hpp).
  telltale::boat::FixLog fix_log({o.log_dir, o.boat_id, boot_id, 100000,
                                  static_cast<std::uint64_t>(o.log_max_mb * 1024 * 1024)});

  telltale::fusion::AlarmEngine alarms;
  alarms.set_rules(default_rules(o), 0);
  std::atomic<bool> shore_rules{false};
  std::atomic<bool> silenced{false};

  std::unique_ptr<telltale::boat::Backfiller> backfiller;
  std::unique_ptr<telltale::boat::EarlierRuns> earlier;
  std::unique_ptr<telltale::boat::FixBackfiller> fix_backfiller;
  std::unique_ptr<telltale::boat::FixEarlierRuns> earlier_fixes;
  telltale::boat::BoatDdsCallbacks callbacks;
  callbacks.on_ack = [&](std::uint64_t boot, std::uint64_t acked, bool new_shore) {
    if (backfiller) backfiller->on_ack(boot, acked, new_shore);
    if (earlier) earlier->on_ack(boot, acked, new_shore);
  };
  callbacks.on_fix_ack = [&](std::uint64_t boot, std::uint64_t acked, bool new_shore) {
    if (fix_backfiller) fix_backfiller->on_ack(boot, acked, new_shore);
    if (earlier_fixes) earlier_fixes->on_ack(boot, acked, new_shore);
  };
  callbacks.on_rules = [&](std::vector<telltale::fusion::AlarmRule> rules) {
    shore_rules = true;
    alarms.set_rules(rules.empty() ? default_rules(o) : std::move(rules), run_clock.now_ns());
  };
  callbacks.on_event = [&](const telltale::msg::AlarmEvent& e) {
    silenced = e.phase() == telltale::msg::ALARM_PHASE_SILENCED;
  };
  telltale::boat::BoatDds dds(o.dds, o.boat_id, callbacks);

  // One message per thread: the sensor loop publishes `out`, the backfill thread its own copy;
  // each filled by the one wire module (boat_wire.hpp), live or from the log alike.
  telltale::msg::BoatAttitude out;
  backfiller = std::make_unique<telltale::boat::Backfiller>(
      telltale::boat::BackfillConfig{boot_id, static_cast<std::uint64_t>(2 * o.rate_hz), 2500,
                                     std::chrono::milliseconds(5000)},
      telltale::boat::SessionLogReader(o.log_dir, o.boat_id, boot_id),
      [&o, &dds, boot_id,
       backfill_msg = telltale::msg::BoatAttitude()](const telltale::boat::LogRecord& r) mutable {
        telltale::boat::to_wire(r, o.boat_id, boot_id, backfill_msg);
        return dds.backfill(backfill_msg);
      });
  // Earlier runs the shore never had in full (stopped out of reach): delivered from the log too.
  earlier = std::make_unique<telltale::boat::EarlierRuns>(
      o.log_dir, o.boat_id, boot_id, std::chrono::hours(24 * o.deliver_earlier_days),
      [&o, &dds, msg = telltale::msg::BoatAttitude()](
          std::uint64_t run, const telltale::boat::LogRecord& r) mutable {
        telltale::boat::to_wire(r, o.boat_id, run, msg);
        return dds.backfill(msg);
      },
      [](const std::string& line) {
        std::printf("boat_node %s\n", line.c_str());
        std::fflush(stdout);
      });
  // The fixes go the same way on their own topics, against their own receipts.
  // Lag: 2 s at the fastest receiver (25 Hz); the live fix of the last seconds may be in flight.
  fix_backfiller = std::make_unique<telltale::boat::FixBackfiller>(
      telltale::boat::BackfillConfig{boot_id, 50, 2500, std::chrono::milliseconds(5000)},
      telltale::boat::FixLogReader(o.log_dir, o.boat_id, boot_id),
      [&o, &dds, boot_id,
       msg = telltale::msg::BoatFix()](const telltale::boat::FixRecord& r) mutable {
        telltale::boat::to_wire(r, o.boat_id, boot_id, msg);
        return dds.backfill(msg);
      });
  earlier_fixes = std::make_unique<telltale::boat::FixEarlierRuns>(
      o.log_dir, o.boat_id, boot_id, std::chrono::hours(24 * o.deliver_earlier_days),
      [&o, &dds, msg = telltale::msg::BoatFix()](
          std::uint64_t run, const telltale::boat::FixRecord& r) mutable {
        telltale::boat::to_wire(r, o.boat_id, run, msg);
        return dds.backfill(msg);
      },
      [](const std::string& line) {
        std::printf("boat_node fixes: %s\n", line.c_str());
        std::fflush(stdout);
      });

  telltale::msg::NodeStatus status;
  status.node_id(o.boat_id);
  status.kind(telltale::msg::NODE_KIND_BOAT);
  status.software_version(TELLTALE_VERSION);
  status.group(o.group);

  telltale::boat::WarningHook hook(o.warn_command, std::chrono::seconds(5));
  const bool tty = isatty(STDOUT_FILENO) != 0;
  telltale::fusion::TelltaleAttitudeParams filter_params;
  filter_params.gyro_range_rad_s = o.gyro_range_dps * M_PI / 180.0;
  filter_params.acc_range_m_s2 = o.acc_range_g * telltale::fusion::kStandardGravity_m_s2;
  filter_params.lever_arm_m = {o.sensor_offset_m[0], o.sensor_offset_m[1], o.sensor_offset_m[2]};
  telltale::fusion::TelltaleAttitudeFilter filter(filter_params);
  // The calibration the filter learnt in an earlier run of this sensor (calibration_store.hpp).
  const std::string calibration_path =
      o.calibration_file == "none"
          ? std::string()
          : (o.calibration_file.empty() ? o.log_dir + "/" + o.boat_id + ".imu-calibration.json"
                                        : o.calibration_file);
  const std::string sensor = sensor_identity(o, source->describe(), seed);
  if (!calibration_path.empty()) {
    std::printf("boat_node calibration: %s\n",
                telltale::boat::restore_calibration(filter, calibration_path, sensor, unix_now_s())
                    .c_str());
    std::fflush(stdout);
  }
  bool calibration_write_failed = false;
  const auto keep_calibration = [&] {
    if (calibration_path.empty() || !filter.state().initialised) return;
    try {
      telltale::boat::save_calibration(calibration_path,
                                       {filter.calibration(), sensor, unix_now_s()});
      calibration_write_failed = false;
    } catch (const std::exception& e) {
      // Said once per failing spell: the node goes on; the last good file stays.
      if (!calibration_write_failed)
        std::fprintf(stderr, "boat_node: calibration not kept: %s\n", e.what());
      calibration_write_failed = true;
    }
  };
  const telltale::fusion::LedPanelParams led_params{o.led_step_deg,
                                                    static_cast<std::uint8_t>(o.leds_per_bar)};

  std::printf(
      "boat_node ready: boat=%s domain=%d source=%s gnss=%s rate=%gHz boot=%016llx log=%s "
      "earlier_runs=%zu earlier_fix_runs=%zu\n",
      o.boat_id.c_str(), dds.domain(), source->describe().c_str(),
      gnss ? gnss->describe().c_str() : (course ? "sim:course" : "none"), o.rate_hz,
      static_cast<unsigned long long>(boot_id), o.log_dir.c_str(), earlier->pending(),
      earlier_fixes->pending());
  std::fflush(stdout);

  const auto start = Clock::now();
  const unsigned long long start_utc_ns = run_clock.at(start);
  const double publish_period_s = 1.0 / o.rate_hz;
  double first_t = std::numeric_limits<double>::quiet_NaN();
  double next_publish_s = 0.0;
  double last_t = -std::numeric_limits<double>::infinity();
  bool imu_started = false;
  telltale::fusion::ImuGateCounts imu_gate;
  double calib_heel = 0.0, calib_pitch = 0.0;
  int calib_n = 0;
  bool calibrating = o.calibrate_s > 0;
  std::uint64_t seq = 0;
  std::uint32_t health = telltale::msg::SENSOR_OK;
  unsigned write_failures = 0, bad_samples = 0;
  auto next_status = start;
  auto next_console = start;
  auto next_flush = start + std::chrono::seconds(1);
  auto next_calibration = start + std::chrono::seconds(60);
  std::string addresses = local_addresses();
  telltale::msg::BoatFix fix_msg;
  std::uint64_t fix_seq = 0;
  std::vector<telltale::boat::GnssFix> fixes;
  telltale::fusion::GroundSpeedHold ground_speed;
  double next_course_s = 0.0;
  // Every fix is logged before it is published, as the attitude is: what the link loses, the
  // fix backfill resends from the log.
  const auto publish_fix = [&](const telltale::boat::GnssFix& f) {
    telltale::boat::FixRecord r;
    r.seq = ++fix_seq;
    r.t_utc_ns = f.t_boat_ns;
    r.gnss_utc_ns = f.gnss_utc_ns;
    r.lat_deg = f.lat_deg;
    r.lon_deg = f.lon_deg;
    r.sog_m_s = f.sog_m_s;
    r.cog_deg = f.cog_deg;
    r.fix = static_cast<std::uint8_t>(f.fix);
    r.satellites = static_cast<std::uint8_t>(f.satellites);
    r.hdop = static_cast<float>(f.hdop);
    (void)fix_log.append(r);  // on failure held in memory, retried, reported in the status
    telltale::boat::to_wire(r, o.boat_id, boot_id, fix_msg);
    if (!dds.publish(fix_msg)) ++write_failures;
    fix_backfiller->on_published(r.seq);
  };

  // A wind instrument on the GNSS's NMEA line: each reading made the true wind with the boat's
  // latest heading (the heading source's, else the COG) and GNSS velocity, then published. A
  // velocity older than 2 s (the receiver gone quiet) is none: an apparent reading then waits.
  // Not logged for backfill: the shore uses the wind as a mean over minutes, of which a lost
  // reading is one of hundreds. A magnetic MWD is skipped (the node knows no declination).
  telltale::msg::BoatWind wind_msg;
  std::uint64_t wind_seq = 0;
  std::vector<telltale::boat::TimedWind> winds;
  constexpr double kVelocityFreshS = 2.0;
  double last_heading_deg = std::numeric_limits<double>::quiet_NaN();
  double last_sog_m_s = std::numeric_limits<double>::quiet_NaN();
  double last_cog_deg = std::numeric_limits<double>::quiet_NaN();
  double last_velocity_t = -1e9;

  while (!shutdown.stop_requested()) {
    const auto sample = source->next();
    if (!sample) break;  // end of a replay
    if (std::isnan(first_t)) first_t = sample->t_s;
    const double t = sample->t_s - first_t;
    if (source->real_time()) {
      // Pace on the sample clock; a stop request wakes the wait.
      const auto due =
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(t));
      if (shutdown.wait_for(due - Clock::now())) break;
    }
    const auto now = Clock::now();
    // Bad input is flagged, never fused: the one IMU gate (the filter's own, run here for the
    // health bits) rejects time going backwards and NaN/Inf; saturation is the filter's to flag.
    const unsigned time_rejections = imu_gate.rejected_time;
    if (telltale::fusion::gate_imu_sample(*sample, {}, imu_started, last_t, imu_gate).verdict ==
        telltale::fusion::ImuVerdict::kReject) {
      health |= imu_gate.rejected_time != time_rejections ? telltale::msg::SENSOR_TIME_BACKWARDS
                                                          : telltale::msg::SENSOR_NON_FINITE;
      ++bad_samples;
      continue;
    }
    // GNSS: the receiver's fixes as they come, and their speed and course for the attitude
    // filter (it takes the boat's own acceleration in turns and speed changes off the specific
    // force), held on the sample clock from the sample they arrived with. The simulated course
    // is fed the same way when the simulated IMU sails it (the race scenario).
    if (gnss) {
      gnss->take(fixes);
      for (const auto& f : fixes) {
        publish_fix(f);
        const bool no_fix = f.fix == telltale::sensors::GnssFixKind::kNone;
        last_sog_m_s = no_fix ? std::numeric_limits<double>::quiet_NaN() : f.sog_m_s;
        last_cog_deg = f.cog_deg;
        last_velocity_t = t;
        ground_speed.on_fix(t, no_fix ? std::numeric_limits<double>::quiet_NaN() : f.sog_m_s,
                            f.cog_deg);
      }
    }
    if (gnss) {
      gnss->take_wind(winds);
      for (const auto& w : winds) {
        const bool fresh = t - last_velocity_t <= kVelocityFreshS;
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const auto tw = telltale::fusion::true_wind(w.reading, last_heading_deg,
                                                    fresh ? last_sog_m_s : nan,
                                                    fresh ? last_cog_deg : nan, nan);
        if (!std::isfinite(tw.from_deg)) continue;  // no heading nor course yet, or no direction
        const telltale::boat::WindRecord rec{++wind_seq, w.t_utc_ns, tw.from_deg, tw.speed_m_s,
                                             telltale::fusion::nmea_wind_source(w.reading.ref)};
        telltale::boat::to_wire(rec, o.boat_id, boot_id, wind_msg);
        if (!dds.publish(wind_msg)) ++write_failures;
      }
    }
    // The simulated course at 10 Hz on the sample clock.
    if (!gnss && course && t + 1e-9 >= next_course_s) {
      next_course_s = t + 0.1;
      const unsigned long long t_ns = start_utc_ns + static_cast<unsigned long long>(t * 1e9);
      if (auto f = course_gate.on_epoch(course->at(t, t_ns), t, t_ns)) {
        publish_fix(*f);
        if (course_is_imu_boat) ground_speed.on_fix(t, f->sog_m_s, f->cog_deg);
      }
    }
    if (gnss || course_is_imu_boat) {
      filter.set_speed(ground_speed.speed_m_s(t), ground_speed.rate_m_s2(t),
                       ground_speed.cog_rate_rad_s(t));
    }
    filter.update(mounting.apply(*sample));

    if (t + 1e-9 >= next_publish_s) {
      next_publish_s += publish_period_s;
      if (next_publish_s < t) next_publish_s = t + publish_period_s;  // after a gap in the data
      const telltale::fusion::AttitudeOutput fused = filter.output();
      const double raw_heel = fused.heel_rad * kRadToDeg;
      const double raw_pitch = fused.pitch_rad * kRadToDeg;
      if (calibrating) {
        calib_heel += raw_heel;
        calib_pitch += raw_pitch;
        ++calib_n;
        if (t >= o.calibrate_s) {
          mounting.heel_offset_deg = calib_heel / calib_n;
          mounting.pitch_offset_deg = calib_pitch / calib_n;
          save_offsets(o.mount_file, mounting);
          std::printf("boat_node calibrated: heel offset %.2f deg, pitch offset %.2f deg -> %s\n",
                      mounting.heel_offset_deg, mounting.pitch_offset_deg, o.mount_file.c_str());
          std::fflush(stdout);
          calibrating = false;
        }
      }
      const double heel = raw_heel - mounting.heel_offset_deg;
      const double pitch = raw_pitch - mounting.pitch_offset_deg;
      telltale::boat::LogRecord r;
      r.seq = ++seq;
      r.t_utc_ns = start_utc_ns + static_cast<unsigned long long>(t * 1e9);
      r.heel_deg = heel;
      r.pitch_deg = pitch;
      r.heading_deg = heading ? heading->tick(now) : std::numeric_limits<double>::quiet_NaN();
      last_heading_deg = r.heading_deg;
      r.heel_rate_deg_s = fused.heel_rate_rad_s * kRadToDeg;
      r.pitch_rate_deg_s = fused.pitch_rate_rad_s * kRadToDeg;
      r.yaw_rate_deg_s = fused.yaw_rate_rad_s * kRadToDeg;
      r.accel_weight = static_cast<float>(fused.acc_weight);
      r.quality = static_cast<float>(health == telltale::msg::SENSOR_OK ? fused.quality
                                                                        : 0.5 * fused.quality);
      alarms.evaluate(o.boat_id, o.group, r.t_utc_ns, heel, pitch);
      const AlarmLevel level = alarms.level_of(o.boat_id);
      const auto leds = telltale::fusion::led_panel(heel, pitch, led_params);
      r.leds[0] = leds.left;
      r.leds[1] = leds.right;
      r.leds[2] = leds.up;
      r.leds[3] = leds.down;
      r.led_count = led_params.leds_per_bar;
      r.level = static_cast<std::uint8_t>(level);
      (void)log.append(r);  // on failure held in memory, retried, reported in the status
      telltale::boat::to_wire(r, o.boat_id, boot_id, out);
      if (!dds.publish(out)) ++write_failures;
      backfiller->on_published(r.seq);
      if (!silenced) hook.on_level(o.boat_id, level, heel, now);
      if (o.console && now >= next_console) {
        next_console = now + std::chrono::milliseconds(200);
        std::printf(
            "%s%s",
            telltale::boat::render_panel(o.boat_id, heel, pitch, leds, o.leds_per_bar, level, tty)
                .c_str(),
            tty ? "\r" : "\n");
        std::fflush(stdout);
      }
    }
    if (now >= next_flush) {
      next_flush = now + std::chrono::seconds(1);
      log.flush();
      fix_log.flush();
    }
    if (now >= next_calibration) {
      next_calibration = now + std::chrono::seconds(60);
      keep_calibration();
    }
    if (now >= next_status) {
      next_status = now + std::chrono::seconds(1);
      if (std::string current = local_addresses(); current != addresses) {
        addresses = std::move(current);
        dds.rejoin();
        std::printf("boat_node rejoined the DDS domain: addresses now %s\n", addresses.c_str());
        std::fflush(stdout);
      }
      std::uint32_t h = health;
      if (heading && heading->degraded()) h |= telltale::msg::SENSOR_HEADING_DEGRADED;
      const auto& diag = filter.diagnostics();
      if (diag.rejected_non_finite) h |= telltale::msg::SENSOR_NON_FINITE;
      if (diag.gyro_saturated || diag.acc_saturated) h |= telltale::msg::SENSOR_SATURATED;
      // The log's trouble first: it is what loses data for good (the text is cut at 128). The
      // bit is what the shore's dashboard shows as a badge; the text says how much is at risk.
      // Both kinds' logs as one: the same disk, the same risk.
      auto log_health = log.health();
      const auto fix_health = fix_log.health();
      log_health.pending_records += fix_health.pending_records;
      log_health.dropped_records += fix_health.dropped_records;
      log_health.write_errors += fix_health.write_errors;
      if (log_health.last_error.empty()) log_health.last_error = fix_health.last_error;
      if (log_health.failing()) h |= telltale::msg::SENSOR_LOG_FAILING;
      std::string text;
      if (log_health.failing()) {
        text = "SESSION LOG FAILING (" + log_health.last_error +
               "): " + std::to_string(log_health.pending_records) + " held in memory";
        if (log_health.dropped_records > 0)
          text += ", " + std::to_string(log_health.dropped_records) + " not logged";
        text += "; ";
      }
      text += h == 0 ? "ok" : "sensor flags " + std::to_string(h);
      if (write_failures) text += "; dds write failures " + std::to_string(write_failures);
      if (log_health.write_errors)
        text += "; session log write errors " + std::to_string(log_health.write_errors);
      if (!backfiller->shore_seen()) text += "; no shore receipt yet";
      if (const auto n = earlier->pending() + earlier_fixes->pending())
        text += "; delivering " + std::to_string(n) + " earlier run(s) from the log";
      if (gnss) {
        const auto gs = gnss->stats();
        if (!gs.connected) text += "; gnss not connected";
        if (gs.gate.epochs == 0) {
          text += "; gnss: no data";
        } else if (gs.gate.fixes == 0) {
          text += "; gnss: no fix";
        }
        if (gs.gate.jumps) text += "; gnss jumps " + std::to_string(gs.gate.jumps);
        const auto bad = gs.nmea.bad_checksum + gs.nmea.malformed + gs.nmea.missing_checksum;
        if (bad) text += "; gnss bad lines " + std::to_string(bad);
        if (std::isfinite(gs.clock_offset_s) && std::abs(gs.clock_offset_s) > 1.0) {
          char buf[48];
          std::snprintf(buf, sizeof buf, "; clock %+.1f s vs gnss", gs.clock_offset_s);
          text += buf;
        }
      }
      status.t_utc_ns(run_clock.now_ns());
      status.uptime_s(std::chrono::duration<double>(now - start).count());
      status.samples_published(seq);
      status.sensor_health(h);
      status.health_text(text.substr(0, 128));
      dds.publish(status);
      health = telltale::msg::SENSOR_OK;  // flags cover the last second
    }
  }
  const auto flush_or_say = [](auto& l, const char* kind) {
    if (l.flush()) return;
    const auto lh = l.health();
    std::fprintf(stderr,
                 "boat_node: session log: %llu %s could not be written (%s); %llu were "
                 "never logged\n",
                 static_cast<unsigned long long>(lh.pending_records), kind, lh.last_error.c_str(),
                 static_cast<unsigned long long>(lh.dropped_records));
  };
  flush_or_say(log, "records");
  flush_or_say(fix_log, "fixes");
  keep_calibration();
  if (o.console && tty) std::printf("\n");
  // Hand the shore what it is missing before going: 3 s if the shore is not heard, up to 10 s
  // while it is (the service manager's stop timeout is longer).
  // The fixes drain beside the attitude, not after it: the bound stays the same.
  auto fixes_drained = std::async(std::launch::async, [&] {
    return fix_backfiller->drain(std::chrono::seconds(3), std::chrono::seconds(10));
  });
  const bool complete = backfiller->drain(std::chrono::seconds(3), std::chrono::seconds(10));
  const bool fixes_complete = fixes_drained.get();
  // Otherwise the next start delivers this run from the log (each kind on its own).
  if (complete) telltale::boat::mark_delivered(o.log_dir, o.boat_id, boot_id);
  if (fixes_complete)
    telltale::boat::mark_delivered<telltale::boat::FixCodec>(o.log_dir, o.boat_id, boot_id);
  const std::size_t earlier_pending = earlier->pending();
  const std::size_t earlier_fixes_pending = earlier_fixes->pending();
  earlier.reset();
  earlier_fixes.reset();
  std::printf(
      "boat_node stopped: boat=%s published=%llu fixes=%llu resent=%llu shore_has_all=%s "
      "bad_samples=%u acked=%llu backfill_failures=%llu earlier_runs_pending=%zu "
      "fixes_resent=%llu fixes_acked=%llu shore_has_all_fixes=%s earlier_fix_runs_pending=%zu\n",
      o.boat_id.c_str(), static_cast<unsigned long long>(seq),
      static_cast<unsigned long long>(fix_seq),
      static_cast<unsigned long long>(backfiller->resent()), complete ? "yes" : "no", bad_samples,
      static_cast<unsigned long long>(backfiller->acked()),
      static_cast<unsigned long long>(backfiller->send_failures()), earlier_pending,
      static_cast<unsigned long long>(fix_backfiller->resent()),
      static_cast<unsigned long long>(fix_backfiller->acked()), fixes_complete ? "yes" : "no",
      earlier_fixes_pending);
}

}  // namespace

int main(int argc, char** argv) {
  telltale::ShutdownSignal shutdown;  // first: every later thread inherits the blocked signals
  Options o;
  int domain = -1;
  CLI::App app{
      "Telltale boat node: IMU (+ heading sensors) -> fusion core -> DDS, with a session "
      "log and backfill"};
  app.set_config("--config", "", "read options from this file (INI/TOML: key = value)");
  // --help groups the flags the way a technician fits a boat: who it is, its sensors, how the
  // sensor sits in the hull, its log, its own alarms, then the link to the shore (DDS).
  const std::string identity = "Identity";
  app.add_option("--boat-id", o.boat_id, "fleet-unique boat id, 1-32 of [A-Za-z0-9_-]")
      ->required()
      ->group(identity);
  app.add_option("--group", o.group, "fleet group or class (alarm rules can target it)")
      ->group(identity);

  const std::string sensors = "Sensors";
  app.add_option("--source", o.source,
                 "IMU: sim (the simulated race course's boat, also sim:race) | sim:SCENARIO "
                 "(dinghy, desk, turntable...: the scenarios `fusion_cli simulate --help` lists) | "
                 "replay:FILE.csv | witmotion:DEVICE[@BAUD]")
      ->capture_default_str()
      ->group(sensors);
  app.add_option("--imu-rate-hz", o.imu_rate_hz, "IMU rate of the sim source, Hz")
      ->capture_default_str()
      ->group(sensors);
  app.add_option("--seed", o.seed, "simulator seed (default: from the boat id)")->group(sensors);
  app.add_option("--gyro-range-dps", o.gyro_range_dps,
                 "gyro full scale (saturation detection); a WitMotion module: 2000")
      ->capture_default_str()
      ->group(sensors);
  app.add_option("--acc-range-g", o.acc_range_g,
                 "accelerometer full scale (saturation detection); a WitMotion module: 16")
      ->capture_default_str()
      ->group(sensors);
  app.add_flag("--replay-fast", o.replay.fast, "replay as fast as possible (default: real time)")
      ->group(sensors);
  app.add_flag("--replay-loop", o.replay.loop, "replay the file again at its end")->group(sensors);

  const std::string gnss_heading = "GNSS and heading";
  app.add_option("--gnss", o.gnss,
                 "GNSS receiver: gpsd[:HOST[:PORT]] | nmea:DEVICE[@BAUD] | nmea:udp:[ADDR:]PORT "
                 "(default with a sim source: the simulated race course)")
      ->group(gnss_heading);
  app.add_option("--heading", o.headings,
                 "heading sensor, repeatable: nmea:DEVICE[@BAUD] | nmea:udp:[ADDR:]PORT")
      ->group(gnss_heading);
  app.add_option("--variation-deg", o.variation_deg,
                 "magnetic variation (E positive) to use HDM/HDG sentences without one")
      ->group(gnss_heading);

  const std::string mounting = "Mounting";
  app.add_option("--axis-remap", o.axis_remap, "boat axes from sensor axes, e.g. x=-y,y=x,z=z")
      ->capture_default_str()
      ->group(mounting);
  app.add_option("--mount-file", o.mount_file,
                 "heel/pitch zero offsets (read, and written by --calibrate-s)")
      ->group(mounting);
  app.add_option("--sensor-offset", o.sensor_offset_m,
                 "where the IMU sits from the boat's centre (pivot, GNSS reference), boat axes in "
                 "m: FORWARD,PORT,UP, e.g. 1.5,0,0.25 on a dinghy's bow (the sim's boats). Its "
                 "swing through a tack is otherwise read as heel")
      ->delimiter(',')
      ->expected(3)
      // Range alone lets "nan" through (every comparison with NaN is false).
      ->check(
          [](const std::string& v) {
            char* end = nullptr;
            const double d = std::strtod(v.c_str(), &end);
            return end != v.c_str() && *end == '\0' && std::isfinite(d)
                       ? std::string()
                       : "'" + v + "' is not a finite number of metres";
          },
          "")
      ->check(CLI::Range(-50.0, 50.0))
      ->capture_default_str()
      ->group(mounting);
  app.add_option("--calibration-file", o.calibration_file,
                 "the IMU calibration the attitude filter learns (gyro bias, scale, skew), kept "
                 "across restarts: read at start when it is this sensor's, written every minute "
                 "and at exit (default LOG_DIR/BOAT_ID.imu-calibration.json; none: not kept)")
      ->group(mounting);
  app.add_option("--calibrate-s", o.calibrate_s,
                 "with the boat level at the dock: average this long and store the offsets")
      ->group(mounting);

  const std::string session_log = "Session log";
  app.add_option("--log-dir", o.log_dir, "session log directory")
      ->capture_default_str()
      ->group(session_log);
  app.add_option("--log-max-mb", o.log_max_mb, "session log disk budget; oldest files go first")
      ->capture_default_str()
      ->group(session_log);
  app.add_option("--deliver-earlier-days", o.deliver_earlier_days,
                 "runs of the last N days the shore never confirmed (stopped out of reach) are "
                 "delivered from the log at start; 0: none")
      ->check(CLI::Range(0, 365))
      ->capture_default_str()
      ->group(session_log);

  const std::string alarms = "Alarms and LED panel";
  app.add_flag("--console", o.console, "show the LED panel on the console")->group(alarms);
  app.add_option("--warn-command", o.warn_command,
                 "command run when the alarm level rises (TELLTALE_LEVEL etc. in its environment)")
      ->group(alarms);
  app.add_option("--led-step-deg", o.led_step_deg, "degrees per LED")
      ->capture_default_str()
      ->group(alarms);
  app.add_option("--leds-per-bar", o.leds_per_bar, "LEDs per bar")
      ->capture_default_str()
      ->check(CLI::Range(1, 20))
      ->group(alarms);
  app.add_option("--default-max-heel-deg", o.default_max_heel_deg,
                 "local alarm when no shore has pushed rules: |heel| above this for 2 s")
      ->capture_default_str()
      ->group(alarms);

  app.add_option("--domain", domain, "DDS domain id (default: $TELLTALE_DOMAIN, else 0)")
      ->group(telltale::dds::kCliGroup);
  app.add_option("--rate-hz", o.rate_hz, "attitude samples published per second, Hz")
      ->capture_default_str()
      ->group(telltale::dds::kCliGroup);
  telltale::dds::add_dds_options(app, o.dds);
  app.add_option("--fault-drop-link", o.fault_drop_link,
                 "testing: drop every packet this node sends from START_S for DURATION_S")
      ->group("Fault injection");
  CLI11_PARSE(app, argc, argv);
  if (domain >= 0) o.dds.domain = domain;
  try {
    inject_link_drop(o);
    run(o, shutdown);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boat_node: %s\n", e.what());
    return 1;
  }
  return 0;
}
