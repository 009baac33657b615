// boat_node: runs the fusion core on a boat's IMU and publishes heel, pitch and heading over DDS.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <regex>
#include <string>

#include "boat_publisher.hpp"
#include "shutdown.hpp"
#include "sim_source.hpp"
#include "telltale/fusion/complementary.hpp"
#include "telltale/fusion/led_panel.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kRadToDeg = 180.0 / M_PI;

struct Options {
  telltale::dds::DdsOptions dds;
  std::string boat_id;
  std::string group;
  std::string source = "sim";
  double rate_hz = 25.0;
  double imu_rate_hz = 100.0;
  std::uint64_t seed = 0;
};

void validate(const Options& o) {
  static const std::regex kId("[A-Za-z0-9_-]{1,32}");
  if (!std::regex_match(o.boat_id, kId))
    throw std::invalid_argument("boat id must be 1-32 of [A-Za-z0-9_-], got '" + o.boat_id + "'");
  if (!o.group.empty() && !std::regex_match(o.group, kId))
    throw std::invalid_argument("group must be 1-32 of [A-Za-z0-9_-], got '" + o.group + "'");
  if (o.source != "sim") throw std::invalid_argument("unknown source '" + o.source + "'");
  if (!(o.imu_rate_hz > 0.0 && o.imu_rate_hz <= 1000.0))
    throw std::invalid_argument("--imu-rate-hz must be in (0, 1000]");
  if (!(o.rate_hz > 0.0 && o.rate_hz <= o.imu_rate_hz))
    throw std::invalid_argument("--rate-hz must be in (0, --imu-rate-hz]");
}

void run(const Options& o, telltale::ShutdownSignal& shutdown) {
  validate(o);
  telltale::boat::BoatPublisher publisher(o.dds, o.boat_id);
  const std::uint64_t seed = o.seed ? o.seed : std::hash<std::string>{}(o.boat_id);
  telltale::boat::SimSource source(seed, o.imu_rate_hz);
  telltale::fusion::ComplementaryFilter filter;

  telltale::msg::BoatAttitude out;
  telltale::dds::assign_bounded<32>(out.boat_id(), o.boat_id, "boat id");
  telltale::msg::NodeStatus status;
  telltale::dds::assign_bounded<32>(status.node_id(), o.boat_id, "boat id");
  status.kind(telltale::msg::NODE_KIND_BOAT);
  status.software_version(TELLTALE_VERSION);
  status.group(o.group);

  std::printf("boat_node ready: boat=%s domain=%d source=%s rate=%gHz\n", o.boat_id.c_str(),
              telltale::dds::resolve_domain(o.dds.domain), o.source.c_str(), o.rate_hz);
  std::fflush(stdout);

  const auto start = Clock::now();
  const unsigned long long start_utc_ns = telltale::utc_now_ns();
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / o.imu_rate_hz));
  const double publish_period_s = 1.0 / o.rate_hz;
  double next_publish_s = 0.0;
  double last_heel = std::numeric_limits<double>::quiet_NaN();
  double last_pitch = last_heel;
  double last_publish_s = 0.0;
  unsigned long long seq = 0;
  auto next_status = start;
  auto tick = start;
  unsigned write_failures = 0;

  while (!shutdown.stop_requested()) {
    const telltale::fusion::ImuSample s = source.next();
    filter.update(s);
    if (s.t_s + 1e-9 >= next_publish_s) {
      next_publish_s += publish_period_s;
      const double heel = filter.heel_rad() * kRadToDeg;
      const double pitch = filter.pitch_rad() * kRadToDeg;
      const double dt = s.t_s - last_publish_s;
      out.seq(++seq);
      out.t_utc_ns(start_utc_ns + static_cast<unsigned long long>(s.t_s * 1e9));
      out.heel_deg(heel);
      out.pitch_deg(pitch);
      out.heading_deg(std::numeric_limits<double>::quiet_NaN());
      out.heel_rate_deg_s(std::isfinite(last_heel) && dt > 0 ? (heel - last_heel) / dt : 0.0);
      out.pitch_rate_deg_s(std::isfinite(last_pitch) && dt > 0 ? (pitch - last_pitch) / dt : 0.0);
      out.yaw_rate_deg_s(s.gyro_body_rad_s.z() * kRadToDeg);
      out.accel_weight(0.0f);
      out.quality(1.0f);
      const auto leds = telltale::fusion::led_panel(heel, pitch);
      out.leds().left_leds(leds.left);
      out.leds().right_leds(leds.right);
      out.leds().up_leds(leds.up);
      out.leds().down_leds(leds.down);
      out.leds().led_count(6);
      out.leds().level(telltale::msg::ALARM_LEVEL_NORMAL);
      if (!publisher.publish(out)) ++write_failures;
      last_heel = heel;
      last_pitch = pitch;
      last_publish_s = s.t_s;
    }
    const auto now = Clock::now();
    if (now >= next_status) {
      next_status += std::chrono::seconds(1);
      const auto& diag = filter.diagnostics();
      status.t_utc_ns(telltale::utc_now_ns());
      status.uptime_s(std::chrono::duration<double>(now - start).count());
      status.samples_published(seq);
      status.sensor_health(diag.rejected_non_finite ? telltale::msg::SENSOR_NON_FINITE
                                                    : telltale::msg::SENSOR_OK);
      status.health_text(write_failures ? "dds write failures" : "ok");
      publisher.publish(status);
    }
    tick += period;
    shutdown.wait_for(tick - Clock::now());
  }
  std::printf("boat_node stopped: boat=%s published=%llu\n", o.boat_id.c_str(), seq);
}

}  // namespace

int main(int argc, char** argv) {
  telltale::ShutdownSignal shutdown;  // first: every later thread inherits the blocked signals
  Options o;
  int domain = -1;
  CLI::App app{"Telltale boat node: IMU -> fusion core -> heel, pitch, heading over DDS"};
  app.add_option("--domain", domain, "DDS domain id (default: $TELLTALE_DOMAIN)");
  app.add_option("--boat-id", o.boat_id, "fleet-unique boat id, 1-32 of [A-Za-z0-9_-]")
      ->required();
  app.add_option("--group", o.group, "fleet group or class (alarm rules can target it)");
  app.add_option("--source", o.source, "sensor source: sim")->capture_default_str();
  app.add_option("--rate-hz", o.rate_hz, "publish rate, Hz")->capture_default_str();
  app.add_option("--imu-rate-hz", o.imu_rate_hz, "IMU sample rate of the sim source, Hz")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "simulator seed (default: derived from the boat id)");
  app.add_option("--dds-profiles", o.dds.profiles_file,
                 "Fast DDS profiles XML (default: $TELLTALE_DDS_PROFILES or deploy/dds/)");
  app.add_option("--dds-participant", o.dds.participant_profile,
                 "participant profile in that file")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (domain >= 0) o.dds.domain = domain;
  try {
    run(o, shutdown);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "boat_node: %s\n", e.what());
    return 1;
  }
  return 0;
}
