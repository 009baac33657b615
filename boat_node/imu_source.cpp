#include "imu_source.hpp"

#include <stdexcept>
#include <vector>

#include "csv.hpp"
#include "telltale/fusion/sim/scenario.hpp"
#include "witmotion_feed.hpp"

namespace telltale::boat {
namespace {

/// A simulator scenario of fusion_core (default: the race, on the course of the node's simulated
/// receiver), endless.
class SimImuSource : public ImuSource {
 public:
  SimImuSource(const std::string& scenario, std::uint64_t seed, double rate_hz)
      : name_(scenario), sim_(fusion::sim::make_scenario(scenario, seed, rate_hz, 0.0)) {
    if (!sim_) throw std::invalid_argument("unknown simulator scenario '" + scenario + "'");
  }
  SimImuSource(std::shared_ptr<fusion::sim::RaceCourse> race, std::uint64_t seed, double rate_hz)
      : name_("race"), sim_(fusion::sim::make_race_scenario(std::move(race), seed, rate_hz, 0.0)) {
    if (!sim_) throw std::invalid_argument("--imu-rate-hz must be positive");
  }
  std::optional<fusion::ImuSample> next() override {
    fusion::ImuSample s;
    fusion::sim::AttitudeTruth truth;
    if (!sim_->next(s, truth)) return std::nullopt;
    return s;
  }
  bool real_time() const override { return true; }
  std::string describe() const override { return "sim:" + name_; }

 private:
  std::string name_;
  std::unique_ptr<fusion::sim::ImuScenario> sim_;
};

/// An IMU CSV of SPEC section 6 (t_s, gyro, accelerometer; any column order).
class ReplayImuSource : public ImuSource {
 public:
  ReplayImuSource(std::string path, ReplayOptions options)
      : path_(std::move(path)), options_(options) {
    open();
  }
  std::optional<fusion::ImuSample> next() override {
    if (!reader_->next(row_)) {
      if (!options_.loop || in_pass_ < 2) return std::nullopt;
      // Start again with time still increasing: one mean sample period after the last sample.
      const double span = last_raw_ - first_raw_;
      offset_s_ += span + span / static_cast<double>(in_pass_ - 1);
      open();
      in_pass_ = 0;
      if (!reader_->next(row_)) return std::nullopt;
    }
    if (in_pass_ == 0) first_raw_ = row_[0];
    last_raw_ = row_[0];
    ++in_pass_;
    fusion::ImuSample s;
    s.t_s = row_[0] + offset_s_;
    s.gyro_body_rad_s = {row_[1], row_[2], row_[3]};
    s.acc_body_m_s2 = {row_[4], row_[5], row_[6]};
    return s;
  }
  bool real_time() const override { return !options_.fast; }
  std::string describe() const override { return "replay:" + path_; }

 private:
  void open() {
    reader_ = std::make_unique<io::CsvReader>(
        path_,
        std::vector<io::CsvColumn>{{"t_s"}, {"gx_rad_s"}, {"gy_rad_s"}, {"gz_rad_s"},
                                   {"ax_m_s2"}, {"ay_m_s2"}, {"az_m_s2"}},
        "t_s");
  }
  std::string path_;
  ReplayOptions options_;
  std::unique_ptr<io::CsvReader> reader_;
  std::vector<double> row_;
  double offset_s_ = 0.0;
  double first_raw_ = 0.0;
  double last_raw_ = 0.0;
  std::uint64_t in_pass_ = 0;
};

/// A WitMotion/JY901 module on a serial port; the device paces the node.
class WitMotionImuSource : public ImuSource {
 public:
  WitMotionImuSource(std::string spec, const std::function<bool()>& stop)
      : spec_(std::move(spec)), feed_(spec_), stop_(stop) {}
  std::optional<fusion::ImuSample> next() override {
    const auto w = feed_.next(stop_);
    if (!w) return std::nullopt;
    return w->imu;
  }
  bool real_time() const override { return false; }
  std::string describe() const override { return "witmotion:" + spec_; }

 private:
  std::string spec_;
  WitMotionFeed feed_;
  std::function<bool()> stop_;
};

}  // namespace

bool is_race_source(const std::string& spec) { return spec == "sim" || spec == "sim:race"; }

std::unique_ptr<ImuSource> make_imu_source(const std::string& spec, std::uint64_t seed,
                                           double sim_rate_hz, const ReplayOptions& replay,
                                           const std::function<bool()>& stop,
                                           std::shared_ptr<fusion::sim::RaceCourse> race) {
  if (spec.rfind("witmotion:", 0) == 0 && spec.size() > 10)
    return std::make_unique<WitMotionImuSource>(spec.substr(10), stop);
  if (is_race_source(spec)) {
    if (!race) race = std::make_shared<fusion::sim::RaceCourse>(seed);
    return std::make_unique<SimImuSource>(std::move(race), seed, sim_rate_hz);
  }
  if (spec.rfind("sim:", 0) == 0)
    return std::make_unique<SimImuSource>(spec.substr(4), seed, sim_rate_hz);
  if (spec.rfind("replay:", 0) == 0 && spec.size() > 7)
    return std::make_unique<ReplayImuSource>(spec.substr(7), replay);
  throw std::invalid_argument("unknown --source '" + spec +
                              "' (sim, sim:SCENARIO, replay:FILE.csv, witmotion:DEVICE[@BAUD])");
}

}  // namespace telltale::boat
