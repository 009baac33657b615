// The production filter on eight real recordings with optical ground truth (BROAD, CC BY 4.0,
// tests/data/broad/README.md). Six: mean inclination RMSE <= 0.45 deg, every trial < 0.6
// (measured: 0.39 mean, worst 0.52; VQF 6D and the filter before the VQF-style rebuild ~0.53 on
// these six, Madgwick's ~2.6 deg). Seen failing: the filter before the VQF-style rebuild gives a
// mean of ~0.54 here. The seventh, trial 08, is the gyro's scale, the eighth, 29, the
// accelerometer's skew (below).
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "broad.hpp"
#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/attitude_eval.hpp"
#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/resample.hpp"

namespace telltale::fusion {
namespace {

/// Inflates a .gz file to a temporary CSV, so the one CSV reader of telltale_io parses it. The
/// name carries the process id: ctest runs this file's tests as parallel processes, and with one
/// name for all, one test removed a trial's CSV while another was reading it (seen in the
/// sanitized suite: "cannot open file").
std::string gunzip_to_temp(const std::string& gz_path) {
  const std::string out =
      (std::filesystem::temp_directory_path() / ("telltale_" + std::to_string(getpid()) + "_" +
                                                 std::filesystem::path(gz_path).stem().string()))
          .string();
  gzFile in = gzopen(gz_path.c_str(), "rb");
  if (in == nullptr) throw std::runtime_error("cannot open " + gz_path);
  std::ofstream os(out, std::ios::binary);
  char buf[1 << 16];
  int n = 0;
  while ((n = gzread(in, buf, sizeof buf)) > 0) os.write(buf, n);
  gzclose(in);
  return out;
}

/// One trial of tests/data/broad, as recorded (286 Hz) or resampled to `rate_hz`.
InclinationTrial read_trial(const std::string& trial, double rate_hz = 0.0) {
  const std::string dir = std::string(TELLTALE_TEST_DATA_DIR) + "/broad/";
  const std::string imu = gunzip_to_temp(dir + trial + ".imu.csv.gz");
  const std::string truth = gunzip_to_temp(dir + trial + ".truth.csv.gz");
  const InclinationTrial data = io::read_broad_trial(imu, truth);
  std::filesystem::remove(imu);
  std::filesystem::remove(truth);
  return resample_trial(data, rate_hz);
}

/// The production filter's inclination RMSE on one trial of tests/data/broad, told the
/// recording's sensor's full scales as every filter judged on it is.
double trial_rmse_deg(const std::string& trial, const TelltaleAttitudeParams& params = {}) {
  const InclinationTrial data = read_trial(trial);
  TelltaleAttitudeFilter filter(with_ranges(params, data.sensor));
  return inclination_rmse_deg(filter, data);
}

/// Seven of the trials in tests/data/broad (29 has its own test); 08 is IMU "A", the others
/// IMU "B".
constexpr const char* kTrials[] = {"02_undisturbed_slow_rotation_B",
                                   "07_undisturbed_fast_rotation_B",
                                   "08_undisturbed_fast_rotation_with_breaks_A",
                                   "11_undisturbed_slow_translation_B",
                                   "16_undisturbed_fast_translation_B",
                                   "25_disturbed_tapping_B",
                                   "27_disturbed_phone_vibration_B"};
constexpr const char* kTrial08 = kTrials[2];

TEST(Broad, ProductionFilterMeanInclinationRmseWithinTarget) {
  double sum = 0.0;
  for (const char* trial : kTrials) {
    if (std::string_view(trial) == kTrial08) continue;  // the gyro's scale: its own test below
    const double e = trial_rmse_deg(trial);
    RecordProperty(trial, std::to_string(e));
    std::printf("  %s: %.3f deg\n", trial, e);
    EXPECT_LT(e, 0.6) << trial;
    sum += e;
  }
  EXPECT_LE(sum / 6.0, 0.45);
}

// Trial 08 (fast rotation with rests, the dataset's IMU "A"): its gyro reads about 0.5 % low on
// every axis (integrating the gyro alone from the optical truth over each burst, the tilt is
// 3-14 deg off at its end, 1-2 deg with the rates scaled up by 0.5-0.6 %). The filter learns
// that common scale in motion (gyro_scale_sigma_init) and holds 0.88 deg (VQF 6D: 1.76); with
// the scale's state switched off it is 1.50 (the filter before the scale was a state).
TEST(Broad, TheGyrosCommonScaleIsLearntOnTrial08) {
  const std::string trial = kTrial08;
  const double e = trial_rmse_deg(trial);
  TelltaleAttitudeParams off;
  off.gyro_scale_sigma_init = 0.0;
  const double e_off = trial_rmse_deg(trial, off);
  std::printf("  %s: %.3f deg (without the scale's state %.3f)\n", trial.c_str(), e, e_off);
  EXPECT_LT(e, 1.0);
  EXPECT_GT(e_off, 1.3);
}

// Trial 29 (IMU "B", three minutes of a hand carrying the sensor around: rotations up to
// 970 deg/s and 2-3 g of acceleration): every fast trial of IMU "B" reads best with its
// accelerometer taken 3.5-5 ms later than the sampling model says (07 0.52 -> 0.49, 16 0.36 ->
// 0.32, 29 0.99 -> 0.69 deg; IMU "A"'s 08 wants none), a skew between the sensor's two signal
// chains. The filter learns it in motion (acc_skew_sigma_init_s): measured -2.84 ms, 0.72 deg;
// with the state switched off 1.02. Seen failing with the skew's measurement column zeroed
// (the state stays 0: 0.99 deg).
TEST(Broad, TheAccelerometersSkewIsLearntOnTrial29) {
  const InclinationTrial data = read_trial("29_disturbed_stationary_magnet_B");
  TelltaleAttitudeFilter filter(with_ranges({}, data.sensor));
  const double e = inclination_rmse_deg(filter, data);
  TelltaleAttitudeParams off;
  off.acc_skew_sigma_init_s = 0.0;
  TelltaleAttitudeFilter without(with_ranges(off, data.sensor));
  const double e_off = inclination_rmse_deg(without, data);
  const double skew_ms = 1e3 * filter.state().acc_skew_s;
  std::printf("  29: %.3f deg, skew %.2f ms (without the state %.3f deg)\n", e, skew_ms, e_off);
  EXPECT_LT(e, 0.8);
  EXPECT_GT(e_off, 0.9);
  EXPECT_GT(skew_ms, -5.0);
  EXPECT_LT(skew_ms, -1.5);
}

// A boat node's IMU runs at 25-100 Hz, not BROAD's 286: the seven trials as a sensor averaging
// to 50 Hz would give them (resample_trial). Measured: 0.36, 1.18, 1.07, 0.45, 0.79, 0.45, 0.39
// deg (mean 0.67; the fast rotations lose most, 8-12 deg per sample), the best baseline on each
// 0.89-22 deg. Bound: mean <= 1.0, and ahead of every baseline on every trial. Seen failing with
// the low-pass's coefficients formed for a fixed 286 Hz sample interval instead of each
// sample's: mean 1.94, trial 08 5.83, trial 02 1.08 behind the plain average's 0.89.
TEST(Broad, AtABoatNodesRateTheFilterHoldsAndLeadsEveryBaseline) {
  double sum = 0.0;
  for (const char* trial : kTrials) {
    const InclinationTrial data = read_trial(trial, 50.0);
    ASSERT_GT(data.imu.size(), 1000u) << trial;
    double e_filter = 0.0;
    for (const auto& name : attitude_filter_names()) {
      auto filter = make_attitude_filter(name, Eigen::Vector3d::Zero(), data.sensor);
      const double e = inclination_rmse_deg(*filter, data);
      std::printf("  %s at 50 Hz, %s: %.3f deg\n", trial, name.c_str(), e);
      if (name == kDefaultAttitudeFilter) {
        e_filter = e;
        sum += e;
      } else {
        EXPECT_LT(e_filter, e) << trial << " against " << name;
      }
    }
  }
  EXPECT_LE(sum / 7.0, 1.0);
}

// At the paper's 25 Hz the fast rotations (07, 08: a hand turning the sensor at hundreds of
// deg/s) are where the sampling model shows, and two rules of the strapdown carry it: the
// coning term of the rotation increment (where the rotation's axis turns, the increments do not
// commute) and the specific force seen at the orientation of the instant it describes (half an
// interval before the increment's end). Measured: 0.40, 1.90, 1.25, 0.47, 1.51, 0.51, 0.42 deg,
// mean 0.92 (16: 1.51; 1.55 with the boat's 2 g range). Bound: mean <= 1.05, trial 08 < 1.5. Seen
// failing without the coning term (mean 1.24, 08 1.91), with the force rotated at the interval's
// end (mean 1.11, 08 2.26), and without both (mean 1.46, 07 3.93, 08 2.84).
TEST(Broad, AtThePapersRateTheStrapdownFollowsFastRotation) {
  double sum = 0.0;
  double e08 = 0.0;
  for (const char* trial : kTrials) {
    const InclinationTrial data = read_trial(trial, 25.0);
    TelltaleAttitudeFilter filter(with_ranges({}, data.sensor));
    const double e = inclination_rmse_deg(filter, data);
    std::printf("  %s at 25 Hz: %.3f deg\n", trial, e);
    if (std::string_view(trial) == kTrial08) e08 = e;
    sum += e;
  }
  EXPECT_LE(sum / 7.0, 1.05);
  EXPECT_LT(e08, 1.5);
}

/// Every trial of tests/data/broad: the seven and 29.
std::vector<std::string> all_trials() {
  std::vector<std::string> v(std::begin(kTrials), std::end(kTrials));
  v.emplace_back("29_disturbed_stationary_magnet_B");
  return v;
}

// Every filter judged on a recording is told its sensor's full scales (InclinationTrial::sensor;
// BROAD's myon aktos-t: 2000 deg/s, 16 g). Trial 16's hand shakes the sensor at up to 9.6 g:
// read as the boat instrument's 2 g part, 7885 of its samples were taken for clipped ones (the
// drift not learnt from them; started in motion 9.16 deg, 29 2.84), none with its own. From
// rest nothing moves (every trial within 0.001 deg). Seen failing with read_broad_trial leaving
// the ranges unknown (the boat's defaults: 7885 saturated).
TEST(Broad, EveryFilterIsToldTheRecordingsSensor) {
  const InclinationTrial data = read_trial("16_undisturbed_fast_translation_B");
  EXPECT_NEAR(data.sensor.gyro_rad_s * 180.0 / M_PI, 2000.0, 1e-9);
  EXPECT_NEAR(data.sensor.acc_m_s2 / kStandardGravity_m_s2, 16.0, 1e-9);
  TelltaleAttitudeFilter told(with_ranges({}, data.sensor));
  TelltaleAttitudeFilter boat;
  for (const ImuSample& s : data.imu) {
    told.update(s);
    boat.update(s);
  }
  EXPECT_EQ(told.diagnostics().acc_saturated, 0u);
  EXPECT_GT(boat.diagnostics().acc_saturated, 7000u);  // what the ranges are there to avoid
  // The factory passes them on: a filter made for the recording counts no clipped reading.
  auto made = make_attitude_filter("telltale", Eigen::Vector3d::Zero(), data.sensor);
  for (const ImuSample& s : data.imu) made->update(s);
  EXPECT_EQ(dynamic_cast<TelltaleAttitudeFilter&>(*made).diagnostics().acc_saturated, 0u);
}

// Started in motion (at each trial's first movement row, nothing learnt at the rest the
// recording begins with; `fusion_cli eval attitude` prints every filter so): until tau has
// passed, the low-pass is the growing mean of everything since the start, whose drift is not
// the Butterworth's response to a bias, scale or skew, so the motion update does not learn from
// it. Measured 0.26, 0.78, 0.77, 0.65, 8.51, 0.77, 0.77, 2.31 deg (mean 1.85; 16's hand shakes
// the sensor at 1-2 g from its first sample, before any bias is known). Bound: the slow rotation,
// the slow translation and the tapping (02, 11, 25) under 1.0 deg each, the mean under 2.2. Seen
// failing with the motion update running on the growing mean: 0.66, 1.61, 1.88 on those three
// (the skew learnt 16 ms in the first second and unlearnt over a minute), mean 2.39 (with the
// boat instrument's 2 g range, before the trials carried their sensor's).
TEST(Broad, StartedInMotionTheFilterLearnsNothingFromItsGrowingMean) {
  double sum = 0.0;
  const auto trials = all_trials();
  for (const auto& trial : trials) {
    const InclinationTrial data = read_trial(trial);
    TelltaleAttitudeFilter filter(with_ranges({}, data.sensor));
    const double e = inclination_rmse_deg(filter, trial_from(data, first_scored(data)));
    std::printf("  %s started in motion: %.3f deg\n", trial.c_str(), e);
    sum += e;
    if (trial.starts_with("02") || trial.starts_with("11") || trial.starts_with("25")) {
      EXPECT_LT(e, 1.0) << trial;
    }
  }
  EXPECT_LT(sum / static_cast<double>(trials.size()), 2.2);
}

// A node restarted in motion with the calibration it had learnt (warm_start; the boat node keeps
// it in a file across restarts): each trial's filter run over the rest before its first
// movement row, then a new filter started there from its calibration(). Measured 0.31, 0.58,
// 0.80, 0.44, 0.46, 0.38, 0.36, 0.82 deg (mean 0.52; never stopped: 0.49). Bound: mean <= 0.6,
// every trial < 1.0. Seen failing with the calibration not handed over (a cold start: mean 2.00,
// 16 9.16).
TEST(Broad, RestartedWithItsCalibrationTheFilterIsAsGoodAsNeverStopped) {
  double sum = 0.0;
  const auto trials = all_trials();
  for (const auto& trial : trials) {
    const InclinationTrial data = read_trial(trial);
    const std::size_t from = first_scored(data);
    const TelltaleAttitudeParams params = with_ranges({}, data.sensor);
    TelltaleAttitudeFilter before(params);
    for (std::size_t i = 0; i < from; ++i) before.update(data.imu[i]);
    TelltaleAttitudeFilter after(params);
    ASSERT_TRUE(after.warm_start(before.calibration(), 0.0));
    const double e = inclination_rmse_deg(after, trial_from(data, from));
    std::printf("  %s restarted in motion: %.3f deg\n", trial.c_str(), e);
    EXPECT_LT(e, 1.0) << trial;
    sum += e;
  }
  EXPECT_LE(sum / static_cast<double>(trials.size()), 0.6);
}

// The boat node stamps samples with Unix time, the recordings from 0: the filter must read the
// same tilt either way. Its durations come from differences of time stamps, which at Unix time
// carry 2^-22 s of rounding (7e-5 of a 286 Hz interval): measured 0.0016 deg at most over the
// eight shared trials, every filter's threshold on time (rest, start, course windows) included.
// Measured on trial 07: 0.0002 deg. Seen failing with the sample times cast to float inside
// update() (a float at Unix time resolves 128 s: nearly every sample refused as not advancing,
// 144 deg off).
TEST(Broad, TheTiltDoesNotDependOnTheTimeOrigin) {
  const InclinationTrial data = read_trial("07_undisturbed_fast_rotation_B");
  TelltaleAttitudeFilter a(with_ranges({}, data.sensor)), b(with_ranges({}, data.sensor));
  double worst_deg = 0.0;
  for (const ImuSample& s : data.imu) {
    ImuSample unix_time = s;
    unix_time.t_s += 1733397600.123;
    a.update(s);
    b.update(unix_time);
    const AttitudeOutput oa = a.output(), ob = b.output();
    worst_deg = std::max(
        worst_deg,
        inclination_error_rad(oa.heel_rad, oa.pitch_rad, ob.heel_rad, ob.pitch_rad) * 180.0 / M_PI);
  }
  std::printf("  from 0 against Unix time: %.5f deg at most\n", worst_deg);
  EXPECT_LT(worst_deg, 0.01);
}

// The evaluation tools' one resampler: 100 Hz to 25 Hz averages the four readings of each
// interval before the output (ending at it), 100 Hz to 200 Hz interpolates, and a reading-less
// stretch stays a gap both ways. Seen failing with the averaging window centred on the output.
TEST(ResampleSpans, AveragesTheIntervalBeforeAndInterpolatesAboveKeepingGaps) {
  std::vector<double> t;
  for (int i = 0; i <= 100; ++i)
    if (i < 40 || i > 60) t.push_back(i / 100.0);  // 0.40-0.60 s lost
  const auto down = resample_spans(t, 25.0);
  ASSERT_GE(down.size(), 2u);
  EXPECT_EQ(down[0].first, 0u);  // t = 0: the first reading alone
  EXPECT_EQ(down[0].last, 0u);
  EXPECT_DOUBLE_EQ(down[1].t_s, 0.04);  // (0, 0.04]: readings 1..4
  EXPECT_EQ(down[1].first, 1u);
  EXPECT_EQ(down[1].last, 4u);
  EXPECT_DOUBLE_EQ(resampled(down[1], [&](std::size_t i) { return t[i]; }), 0.025);
  for (const auto& s : down) EXPECT_FALSE(s.t_s > 0.44 && s.t_s < 0.6) << s.t_s;  // the gap
  const auto up = resample_spans(t, 200.0);
  ASSERT_GE(up.size(), 3u);
  EXPECT_TRUE(up[1].interpolated);
  EXPECT_DOUBLE_EQ(resampled(up[1], [&](std::size_t i) { return t[i]; }), 0.005);
  for (const auto& s : up) EXPECT_FALSE(s.t_s > 0.4 && s.t_s < 0.6) << s.t_s;
}

}  // namespace
}  // namespace telltale::fusion
