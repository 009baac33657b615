// wearable_node: an athlete's phone or foot IMU on land -> step detection and dead reckoning
// (fusion_core PDR) -> WearableMotion over the same DDS as the boats.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <regex>

#include "boat_wire.hpp"
#include "csv.hpp"
#include "dds_cli.hpp"
#include "dds_participant.hpp"
#include "dds_security.hpp"
#include "run_clock.hpp"
#include "shutdown.hpp"
#include "telltale/fusion/foot_pdr.hpp"
#include "telltale/fusion/handheld_pdr.hpp"
#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/trunk_pdr.hpp"
#include "telltalePubSubTypes.h"
#include "witmotion_feed.hpp"

namespace {

using Clock = std::chrono::steady_clock;
namespace fusion = telltale::fusion;

struct Options {
  telltale::dds::DdsOptions dds;
  std::string athlete_id;
  std::string source = "sim";
  std::string mount = "phone";
  double height_m = 1.75;
  double step_scale = 1.0;  ///< personal factor from a calibration walk (fusion_cli pdr)
  double rate_hz = 2.0;
  std::uint64_t seed = 1;
  bool replay_fast = false;
};

struct Sample {
  fusion::ImuSample imu;
  Eigen::Vector3d mag_uT;
};

/// Samples from the chosen source, in time order; nothing at the end.
class WearableSource {
 public:
  virtual ~WearableSource() = default;
  virtual std::optional<Sample> next(telltale::ShutdownSignal& shutdown) = 0;
  virtual bool real_time() const = 0;
};

/// The gait simulator, walk after walk (each with its own seed), time continuing.
class SimWearable : public WearableSource {
 public:
  SimWearable(std::string scenario, std::uint64_t seed)
      : scenario_(std::move(scenario)), seed_(seed) {
    if (!fusion::sim::make_gait_scenario(scenario_, seed_))
      throw std::invalid_argument("unknown gait scenario '" + scenario_ + "'");
  }
  std::optional<Sample> next(telltale::ShutdownSignal&) override {
    if (i_ >= run_.samples.size()) {
      const auto sc = fusion::sim::make_gait_scenario(scenario_, seed_);
      offset_s_ = run_.samples.empty() ? 0.0 : run_.samples.back().imu.t_s + offset_s_ + 0.02;
      run_ = fusion::sim::simulate_gait(*sc, fusion::sim::random_person(seed_), seed_);
      ++seed_;
      i_ = 0;
      if (run_.samples.empty()) return std::nullopt;
    }
    const auto& g = run_.samples[i_++];
    Sample s{g.imu, g.mag_uT};
    s.imu.t_s += offset_s_;
    return s;
  }
  bool real_time() const override { return true; }

 private:
  std::string scenario_;
  std::uint64_t seed_;
  fusion::sim::GaitRun run_;
  std::size_t i_ = 0;
  double offset_s_ = 0.0;
};

/// An IMU CSV (SPEC section 6): gyro and magnetometer columns optional.
class ReplayWearable : public WearableSource {
 public:
  ReplayWearable(const std::string& path, bool fast)
      : reader_(path,
                {{"t_s"},
                 {"ax_m_s2"},
                 {"ay_m_s2"},
                 {"az_m_s2"},
                 {"gx_rad_s", false, false},
                 {"gy_rad_s", false, false},
                 {"gz_rad_s", false, false},
                 {"mx_uT", false, false},
                 {"my_uT", false, false},
                 {"mz_uT", false, false}},
                "t_s"),
        fast_(fast) {}
  std::optional<Sample> next(telltale::ShutdownSignal&) override {
    if (!reader_.next(row_)) return std::nullopt;
    Sample s;
    s.imu.t_s = row_[0];
    s.imu.acc_body_m_s2 = {row_[1], row_[2], row_[3]};
    s.imu.gyro_body_rad_s = {row_[4], row_[5], row_[6]};  // NaN when absent: "no gyro"
    s.mag_uT = {row_[7], row_[8], row_[9]};
    return s;
  }
  bool real_time() const override { return !fast_; }

 private:
  telltale::io::CsvReader reader_;
  std::vector<double> row_;
  bool fast_;
};

/// A WitMotion/JY901 module on a serial port (the module of paper 004).
class WitMotionWearable : public WearableSource {
 public:
  explicit WitMotionWearable(const std::string& device_and_baud) : feed_(device_and_baud) {}
  std::optional<Sample> next(telltale::ShutdownSignal& shutdown) override {
    const auto w = feed_.next([&] { return shutdown.stop_requested(); });
    if (!w) return std::nullopt;
    return Sample{w->imu,
                  w->has_mag ? w->mag_uT
                             : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN())};
  }
  bool real_time() const override { return false; }  // the device paces itself

 private:
  telltale::boat::WitMotionFeed feed_;
};

std::unique_ptr<WearableSource> make_source(const Options& o) {
  // The simulated walker carries the sensor the way the mount says: a phone held in front for
  // `phone` (what HandheldPdr is for), a belt sensor on a walk for `trunk`, a phone switching
  // poses for `body` and `foot` (as before).
  if (o.source == "sim")
    return std::make_unique<SimWearable>(o.mount == "phone"   ? "phone-hand-held-walk"
                                         : o.mount == "trunk" ? "body-walk"
                                                              : "phone-switch",
                                         o.seed);
  if (o.source.rfind("sim:", 0) == 0)
    return std::make_unique<SimWearable>(o.source.substr(4), o.seed);
  if (o.source.rfind("replay:", 0) == 0)
    return std::make_unique<ReplayWearable>(o.source.substr(7), o.replay_fast);
  if (o.source.rfind("witmotion:", 0) == 0)
    return std::make_unique<WitMotionWearable>(o.source.substr(10));
  throw std::invalid_argument("unknown --source '" + o.source +
                              "' (sim, sim:SCENARIO, replay:FILE.csv, witmotion:DEVICE[@BAUD])");
}

/// Samples the PDR's gate refused (non-finite, or time not after the last).
unsigned rejected(const fusion::ImuGateCounts& c) {
  return c.rejected_non_finite + c.rejected_time;
}

void run(const Options& o, telltale::ShutdownSignal& shutdown) {
  static const std::regex kId("[A-Za-z0-9_-]{1,32}");
  if (!std::regex_match(o.athlete_id, kId))
    throw std::invalid_argument("athlete id must be 1-32 of [A-Za-z0-9_-]");
  if (!(o.height_m >= 1.0 && o.height_m <= 2.5))
    throw std::invalid_argument("--height-m must be in 1.0..2.5");
  if (!(o.step_scale >= 0.5 && o.step_scale <= 1.5))
    throw std::invalid_argument("--step-scale must be in 0.5..1.5");
  if (!(o.rate_hz > 0 && o.rate_hz <= 50)) throw std::invalid_argument("--rate-hz in (0, 50]");
  if (o.mount != "phone" && o.mount != "body" && o.mount != "foot" && o.mount != "trunk")
    throw std::invalid_argument("--mount is phone, body, foot or trunk");
  const bool foot = o.mount == "foot";
  const bool trunk = o.mount == "trunk";
  const bool handheld = o.mount == "phone";
  auto source = make_source(o);
  // One pipeline per mount, the same as `fusion_cli pdr --mount`: phone -> HandheldPdr (a phone
  // held in front), body -> the seed-003 Pdr with its four poses, foot -> FootPdr, trunk ->
  // TrunkPdr.
  std::unique_ptr<fusion::Pdr> pdr;  // 110 kB: not on the stack
  std::unique_ptr<fusion::FootPdr> foot_pdr;
  std::unique_ptr<fusion::TrunkPdr> trunk_pdr;
  std::unique_ptr<fusion::HandheldPdr> phone_pdr;
  if (handheld) {
    fusion::HandheldPdrParams hp;
    hp.height_m = o.height_m;
    hp.step_scale = o.step_scale;
    phone_pdr = std::make_unique<fusion::HandheldPdr>(hp);
  } else if (foot) {
    foot_pdr = std::make_unique<fusion::FootPdr>();  // the stride is measured: no height
  } else if (trunk) {
    fusion::TrunkPdrParams tp;  // each step measured: the height is the pendulum's leg
    tp.height_m = o.height_m;
    trunk_pdr = std::make_unique<fusion::TrunkPdr>(tp);
  } else {
    fusion::PdrParams params;
    params.step_length.height_m = o.height_m;
    params.step_length.scale.fill(o.step_scale);
    pdr = std::make_unique<fusion::Pdr>(params);
  }
  unsigned rejected_non_finite = 0;  // HandheldPdr drops such samples without counting them

  auto dds_options = o.dds;
  telltale::dds::use_node_partitions(dds_options, o.athlete_id);  // secured: its own only
  telltale::dds::Participant participant(dds_options, "wearable_node " + o.athlete_id);
  namespace fdds = eprosima::fastdds::dds;
  auto* motion_writer = participant.writer(
      participant.topic(telltale::dds::kTopicWearableMotion,
                        fdds::TypeSupport(new telltale::msg::WearableMotionPubSubType())),
      "wearable_writer");
  auto* status_writer = participant.writer(
      participant.topic(telltale::dds::kTopicNodeStatus,
                        fdds::TypeSupport(new telltale::msg::NodeStatusPubSubType())),
      "status_writer");
  telltale::msg::WearableMotion m;
  telltale::msg::NodeStatus status;
  status.node_id(o.athlete_id);
  status.kind(telltale::msg::NODE_KIND_WEARABLE);
  status.software_version(TELLTALE_VERSION);

  std::printf("wearable_node ready: athlete=%s domain=%d source=%s\n", o.athlete_id.c_str(),
              participant.domain(), o.source.c_str());
  std::fflush(stdout);

  // Every record of this run is stamped on one clock (run_clock.hpp says why).
  const telltale::boat::RunClock run_clock;
  const auto start = Clock::now();
  const unsigned long long start_utc = run_clock.at(start);
  double first_t = std::numeric_limits<double>::quiet_NaN();
  double next_publish = 0.0;
  auto next_status = start;
  std::uint64_t seq = 0;
  while (!shutdown.stop_requested()) {
    const auto s = source->next(shutdown);
    if (!s) break;
    if (std::isnan(first_t)) first_t = s->imu.t_s;
    const double t = s->imu.t_s - first_t;
    if (source->real_time()) {
      const auto due =
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(t));
      if (shutdown.wait_for(due - Clock::now())) break;
    }
    fusion::PdrOutput handheld_out;
    if (handheld) {
      if (!s->imu.acc_body_m_s2.allFinite() || !s->imu.gyro_body_rad_s.allFinite())
        ++rejected_non_finite;
      phone_pdr->update(s->imu, s->mag_uT);
      const auto& h = phone_pdr->last();
      handheld_out.steps = h.steps;
      handheld_out.step_hz = phone_pdr->walking() ? h.step_hz : 0.0;
      handheld_out.cadence_spm = 60.0 * handheld_out.step_hz;
      handheld_out.gait = fusion::gait_of_step_hz(handheld_out.step_hz);
      handheld_out.pose = fusion::PhonePose::kHandHeld;
      handheld_out.x_m = h.x_m;
      handheld_out.y_m = h.y_m;
      handheld_out.heading_deg = h.heading_deg;
      handheld_out.distance_m = h.distance_m;
    }
    const fusion::PdrOutput& p = handheld ? handheld_out
                                 : foot   ? foot_pdr->update(s->imu, s->mag_uT)
                                 : trunk  ? trunk_pdr->update(s->imu, s->mag_uT)
                                          : pdr->update(s->imu, s->mag_uT);
    if (t >= next_publish) {
      next_publish = t + 1.0 / o.rate_hz;
      const auto mount = foot    ? telltale::boat::WearableMount::kFoot
                         : trunk ? telltale::boat::WearableMount::kTrunk
                                 : telltale::boat::WearableMount::kCarried;
      telltale::boat::to_wire(
          {++seq, start_utc + static_cast<unsigned long long>(t * 1e9), p, mount}, o.athlete_id, m);
      motion_writer->write(&m);
    }
    if (Clock::now() >= next_status) {
      next_status += std::chrono::seconds(1);
      const unsigned bad = handheld ? rejected_non_finite
                           : foot   ? rejected(foot_pdr->diagnostics())
                           : trunk  ? rejected(trunk_pdr->diagnostics())
                                    : rejected(pdr->diagnostics());
      status.t_utc_ns(run_clock.now_ns());
      status.uptime_s(std::chrono::duration<double>(Clock::now() - start).count());
      status.samples_published(seq);
      status.sensor_health(bad ? telltale::msg::SENSOR_NON_FINITE : telltale::msg::SENSOR_OK);
      status.health_text(bad ? "non-finite samples rejected" : "ok");
      status_writer->write(&status);
    }
  }
  std::printf("wearable_node stopped: athlete=%s published=%llu\n", o.athlete_id.c_str(),
              static_cast<unsigned long long>(seq));
}

}  // namespace

int main(int argc, char** argv) {
  telltale::ShutdownSignal shutdown;
  Options o;
  int domain = -1;
  CLI::App app{"Telltale wearable node: phone/foot IMU -> steps and dead reckoning -> DDS"};
  app.set_config("--config", "", "read options from this file (INI/TOML: key = value)");
  // --help: who wears it, the sensor and how it is worn, the athlete's step, then the link.
  app.add_option("--athlete-id", o.athlete_id, "athlete id, 1-32 of [A-Za-z0-9_-]")
      ->required()
      ->group("Identity");

  const std::string sensor = "Sensor";
  app.add_option("--source", o.source,
                 "sim | sim:SCENARIO | replay:FILE.csv | witmotion:DEVICE[@BAUD]")
      ->capture_default_str()
      ->group(sensor);
  app.add_option("--mount", o.mount,
                 "phone (held in front: HandheldPdr, as fusion_cli pdr --mount phone) | body "
                 "(carried in any of the seed-003 poses) | foot (toe-mounted module) | trunk (a "
                 "belt or lower-back module: each step measured by the inverted pendulum)")
      ->capture_default_str()
      ->group(sensor);
  app.add_option("--seed", o.seed, "simulator seed")->capture_default_str()->group(sensor);
  app.add_flag("--replay-fast", o.replay_fast, "replay as fast as possible")->group(sensor);

  const std::string step = "Step length";
  app.add_option("--height-m", o.height_m,
                 "athlete's height (step length model; the trunk's pendulum leg is 0.53 of it; a "
                 "foot's strides are measured)")
      ->capture_default_str()
      ->group(step);
  app.add_option("--step-scale", o.step_scale,
                 "personal step-length factor: known length / distance measured by "
                 "`fusion_cli pdr` on a calibration walk")
      ->capture_default_str()
      ->group(step);

  app.add_option("--domain", domain, "DDS domain id (default: $TELLTALE_DOMAIN, else 0)")
      ->group(telltale::dds::kCliGroup);
  app.add_option("--rate-hz", o.rate_hz, "publish rate")
      ->capture_default_str()
      ->group(telltale::dds::kCliGroup);
  telltale::dds::add_dds_options(app, o.dds);
  CLI11_PARSE(app, argc, argv);
  if (domain >= 0) o.dds.domain = domain;
  try {
    run(o, shutdown);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wearable_node: %s\n", e.what());
    return 1;
  }
  return 0;
}
