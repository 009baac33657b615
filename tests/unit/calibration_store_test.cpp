// The boat node's IMU calibration file (calibration_store.hpp): written and read back bit for
// bit; whatever else is at the path (nothing, garbage, another format, a field missing or of
// the wrong type) is no calibration, with the reason, and never an exception; a full disk
// leaves the previous file as it was.
#include "calibration_store.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "small_tmpfs.hpp"
#include "temp_dir_test.hpp"

namespace telltale::boat {
namespace {

class CalibrationStore : public test::TempDirTest {
 protected:
  CalibrationStore() : TempDirTest("telltale_calibration_") {}
  static SavedCalibration sample() {
    SavedCalibration c;
    c.sensor = "sim:race seed=7 remap=x=x,y=y,z=z gyro=250dps acc=2g";
    c.saved_unix_s = 1796000000.123456;
    c.calibration.bias_rad_s = {0.0123456789012345, -0.1, 1.0 / 3.0};
    c.calibration.gyro_scale = 0.0041;
    c.calibration.acc_skew_s = -0.0027;
    for (int r = 0; r < 5; ++r)
      for (int k = 0; k < 5; ++k) c.calibration.cov(r, k) = 1e-9 * (1 + r + k) + (r == k);
    return c;
  }
  void write(const std::string& text) const { std::ofstream(file()) << text; }
  [[nodiscard]] std::string file() const { return (dir_ / "cal.json").string(); }
};

TEST_F(CalibrationStore, RoundTripsBitForBit) {
  const SavedCalibration c = sample();
  save_calibration(file(), c);
  std::string why;
  const auto got = load_calibration(file(), why);
  ASSERT_TRUE(got) << why;
  EXPECT_EQ(got->sensor, c.sensor);
  EXPECT_EQ(got->saved_unix_s, c.saved_unix_s);
  EXPECT_EQ(got->calibration.bias_rad_s, c.calibration.bias_rad_s);
  EXPECT_EQ(got->calibration.gyro_scale, c.calibration.gyro_scale);
  EXPECT_EQ(got->calibration.acc_skew_s, c.calibration.acc_skew_s);
  EXPECT_EQ(got->calibration.cov, c.calibration.cov);
  EXPECT_FALSE(std::filesystem::exists(file() + ".tmp"));
}

// Seen failing with the parser allowed to throw (the node stopped on a garbled file), and with
// the format read by json::value (a format of another type threw out of load_calibration).
TEST_F(CalibrationStore, AnythingElseIsNoCalibrationWithItsReason) {
  std::string why;
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_EQ(why, "none yet");
  write("{\"format\": \"telltale-imu-calibration\", \"version\": 1, \"sens");
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_EQ(why, "not JSON");
  write("[1, 2, 3]");
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_EQ(why, "not JSON");
  write("{\"format\": \"something-else\", \"version\": 1}");
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_NE(why.find("not a telltale-imu-calibration file"), std::string::npos) << why;
  // The format and version of another type (json::value would throw on them).
  write("{\"format\": 3, \"version\": \"1\"}");
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_NE(why.find("not a telltale-imu-calibration file"), std::string::npos) << why;
  write("{\"format\": \"telltale-imu-calibration\", \"version\": [1]}");
  EXPECT_FALSE(load_calibration(file(), why));
  EXPECT_NE(why.find("not a telltale-imu-calibration file"), std::string::npos) << why;
  // Each field missing or of the wrong type in turn, from a good file.
  save_calibration(file(), sample());
  std::string good;
  {
    std::ifstream in(file());
    good.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto mangled = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    write(text);
    std::string reason;
    const bool loaded = load_calibration(file(), reason).has_value();
    EXPECT_NE(reason.find("bad or missing field"), std::string::npos) << from << ": " << reason;
    return !loaded;
  };
  EXPECT_TRUE(mangled("\"bias_rad_s\"", "\"bias\""));
  EXPECT_TRUE(mangled("\"gyro_scale\": 0.0041", "\"gyro_scale\": \"0.0041\""));
  EXPECT_TRUE(mangled("\"acc_skew_s\": -0.0027", "\"acc_skew_s\": null"));
  EXPECT_TRUE(mangled("\"covariance\"", "\"cov\""));
  EXPECT_TRUE(mangled("\"sensor\": \"sim", "\"sensor\": 3, \"x\": \"sim"));
  EXPECT_TRUE(mangled("\"saved_unix_s\"", "\"saved\""));
}

// A full disk (a real 64 kB tmpfs filled by a ballast file): the write throws naming the file,
// the previous calibration is still there whole, and no temporary file is left. Seen failing
// with the file written in place (a truncated, unreadable calibration).
TEST_F(CalibrationStore, AFullDiskLeavesThePreviousFile) {
  const test::SmallTmpfs disk(dir_, "size=64k,mode=0755");
  ASSERT_TRUE(disk.mounted)
      << "needs root and mount namespaces (a fault test fails, never skips, without them)";
  SavedCalibration before = sample();
  save_calibration(file(), before);
  test::fill_disk(dir_ / "ballast");
  SavedCalibration after = sample();
  after.calibration.gyro_scale = -0.002;
  after.sensor.append(std::string(8192, 'x'));  // more than a page: the write cannot fit
  try {
    save_calibration(file(), after);
    ADD_FAILURE() << "written to a full disk";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file()), std::string::npos) << e.what();
  }
  std::string why;
  const auto got = load_calibration(file(), why);
  ASSERT_TRUE(got) << why;
  EXPECT_EQ(got->calibration.gyro_scale, before.calibration.gyro_scale);
  EXPECT_FALSE(std::filesystem::exists(file() + ".tmp"));
}

// The node's start: the same sensor's file starts the filter from it, its age counted; another
// sensor's, a clock set back (the file saved after now) and no file are cold starts, each said.
// Seen failing with the sensor not compared (another seed's bias taken).
TEST_F(CalibrationStore, ARestartBeginsFromItsOwnSensorsCalibrationOnly) {
  const SavedCalibration c = sample();
  fusion::ImuSample first;
  first.acc_body_m_s2 = {0.0, 0.0, fusion::kStandardGravity_m_s2};
  const auto bias_after = [&](const std::string& sensor, double now, std::string& said) {
    fusion::TelltaleAttitudeFilter f;
    said = restore_calibration(f, file(), sensor, now);
    f.update(first);
    return f.calibration().bias_rad_s;
  };
  std::string said;
  EXPECT_TRUE(bias_after(c.sensor, c.saved_unix_s, said).isZero());
  EXPECT_EQ(said, file() + ": none yet; cold start");
  save_calibration(file(), c);
  EXPECT_EQ(bias_after(c.sensor, c.saved_unix_s + 90.0, said), c.calibration.bias_rad_s);
  EXPECT_NE(said.find(": warm start, saved 90 s ago, gyro bias 0.707 -5.730 19.099 deg/s"),
            std::string::npos)
      << said;
  EXPECT_TRUE(
      bias_after("sim:race seed=8 remap=x=x,y=y,z=z gyro=250dps acc=2g", c.saved_unix_s, said)
          .isZero());
  EXPECT_NE(said.find("is of another sensor"), std::string::npos) << said;
  EXPECT_TRUE(bias_after(c.sensor, c.saved_unix_s - 3600.0, said).isZero());
  EXPECT_NE(said.find("refused (saved -3600 s ago"), std::string::npos) << said;
}

}  // namespace
}  // namespace telltale::boat
