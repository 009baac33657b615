// libFuzzer target: every CSV format Telltale reads (fusion_core/io), through the same reader
// calls as the programs that read them. The first byte picks the format, the rest is the file.
//
// Invariants beyond "no crash": bad input is a CsvError whose message is one line starting with
// "FILE:LINE:COLUMN:"; a returned value is finite unless its column allows missing values (then
// finite or NaN); the time column is finite and strictly increasing; what was read, written by
// CsvWriter and read again, is the same numbers to CsvWriter's 9 significant digits.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "broad.hpp"
#include "csv.hpp"
#include "fuzz_support.hpp"
#include "gait_io.hpp"

namespace {

using telltale::io::CsvColumn;
using telltale::io::CsvError;

/// An in-memory file with a path the reader can open (no disk I/O per run).
class MemFile {
 public:
  explicit MemFile(const char* name) : fd_(memfd_create(name, 0)) {
    if (fd_ < 0) telltale::fuzz::fail(__FILE__, __LINE__, "memfd_create failed");
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  void set(std::string_view content) {
    FUZZ_CHECK(ftruncate(fd_, 0) == 0);
    FUZZ_CHECK(pwrite(fd_, content.data(), content.size(), 0) ==
               static_cast<ssize_t>(content.size()));
  }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  int fd_;
  std::string path_;
};

/// "PATH:LINE:COLUMN: what", one line.
void check_error(const CsvError& e, const std::string& path) {
  const std::string m = e.what();
  FUZZ_CHECK(m.find('\n') == std::string::npos);
  FUZZ_CHECK(m.compare(0, path.size() + 1, path + ":") == 0);
  std::size_t i = path.size() + 1;
  for (int field = 0; field < 2; ++field) {
    const std::size_t digits_from = i;
    while (i < m.size() && m[i] >= '0' && m[i] <= '9') ++i;
    FUZZ_CHECK(i > digits_from);
    FUZZ_CHECK(i < m.size() && m[i] == ':');
    ++i;
  }
}

/// The IMU/heading/truth layouts of SPEC section 6, as their readers request them.
std::vector<CsvColumn> columns_for(std::uint8_t format, std::string* time_column) {
  *time_column = "t_s";
  switch (format % 4) {
    case 0:  // fusion_cli attitude, boat_node replay:, BROAD .imu.csv
      return {{"t_s"},     {"gx_rad_s"}, {"gy_rad_s"}, {"gz_rad_s"},
              {"ax_m_s2"}, {"ay_m_s2"},  {"az_m_s2"}};
    case 1: {  // fusion_cli heading: h1_deg required, h2..h8 optional, empty cells allowed
      std::vector<CsvColumn> cols{{"t_s"}};
      for (int i = 1; i <= 8; ++i) cols.push_back({"h" + std::to_string(i) + "_deg", i == 1, true});
      return cols;
    }
    case 2:  // wearable_node replay:, fusion_cli steps/pdr (gait_io.cpp)
      return {{"t_s"},
              {"ax_m_s2"},
              {"ay_m_s2"},
              {"az_m_s2"},
              {"gx_rad_s", false},
              {"gy_rad_s", false},
              {"gz_rad_s", false},
              {"mx_uT", false, true},
              {"my_uT", false, true},
              {"mz_uT", false, true}};
    default:  // BROAD .truth.csv
      return {{"t_s"}, {"heel_deg", true, true}, {"pitch_deg", true, true}, {"movement"}};
  }
}

/// Streams the file through CsvReader checking every row; returns the rows read.
std::vector<std::vector<double>> read_checked(const std::string& path,
                                              const std::vector<CsvColumn>& cols,
                                              const std::string& time_column) {
  std::vector<std::vector<double>> rows;
  try {
    telltale::io::CsvReader reader(path, cols, time_column);
    std::vector<double> row;
    double last_t = -std::numeric_limits<double>::infinity();
    std::size_t last_line = reader.line();
    while (reader.next(row)) {
      FUZZ_CHECK(row.size() == cols.size());
      FUZZ_CHECK(reader.line() > last_line);
      last_line = reader.line();
      for (std::size_t i = 0; i < cols.size(); ++i) {
        if (!reader.has_column(cols[i].name)) {
          FUZZ_CHECK(std::isnan(row[i]));
        } else if (cols[i].allow_missing) {
          FUZZ_CHECK(std::isfinite(row[i]) || std::isnan(row[i]));
        } else {
          FUZZ_CHECK(std::isfinite(row[i]));
        }
      }
      FUZZ_CHECK(std::isfinite(row[0]) && row[0] > last_t);
      last_t = row[0];
      rows.push_back(row);
    }
  } catch (const CsvError& e) {
    check_error(e, path);
  }
  return rows;
}

/// CsvWriter's output read back gives the same numbers to 9 significant digits.
void check_round_trip(MemFile& scratch, const std::vector<CsvColumn>& cols,
                      const std::vector<std::vector<double>>& rows) {
  if (rows.empty()) return;
  std::vector<std::string> header;
  std::vector<CsvColumn> all;
  for (const auto& c : cols) {
    header.push_back(c.name);
    all.push_back({c.name, true, true});
  }
  {
    telltale::io::CsvWriter writer(scratch.path(), header);
    for (const auto& r : rows) writer.row(r);
    writer.close();
  }
  telltale::io::CsvReader back(scratch.path(), all);
  std::vector<double> got;
  for (const auto& r : rows) {
    FUZZ_CHECK(back.next(got));
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (std::isnan(r[i])) {
        FUZZ_CHECK(std::isnan(got[i]));
        continue;
      }
      // %.9g: relative error below 5e-9; subnormals keep fewer digits, hence the absolute term.
      FUZZ_CHECK(std::fabs(got[i] - r[i]) <= 1e-8 * std::fabs(r[i]) + 1e-300);
    }
  }
  FUZZ_CHECK(!back.next(got));
}

void fuzz_broad(MemFile& imu, MemFile& truth, std::string_view content) {
  // The BROAD pair: both files from one input, split at the first form feed.
  const std::size_t cut = content.find('\f');
  imu.set(content.substr(0, cut));
  truth.set(cut == std::string_view::npos ? std::string_view() : content.substr(cut + 1));
  try {
    const auto trial = telltale::io::read_broad_trial(imu.path(), truth.path());
    const std::size_t n = trial.imu.size();
    FUZZ_CHECK(n > 0);
    FUZZ_CHECK(trial.heel_true_rad.size() == n && trial.pitch_true_rad.size() == n &&
               trial.scored.size() == n);
    for (std::size_t i = 0; i < n; ++i) {
      FUZZ_CHECK(std::isfinite(trial.imu[i].t_s) && trial.imu[i].gyro_body_rad_s.allFinite() &&
                 trial.imu[i].acc_body_m_s2.allFinite());
      if (i > 0) FUZZ_CHECK(trial.imu[i].t_s > trial.imu[i - 1].t_s);
      if (trial.scored[i])
        FUZZ_CHECK(std::isfinite(trial.heel_true_rad[i]) && std::isfinite(trial.pitch_true_rad[i]));
    }
  } catch (const CsvError& e) {
    const std::string m = e.what();
    FUZZ_CHECK(m.find('\n') == std::string::npos);
    FUZZ_CHECK(m.rfind(imu.path() + ":", 0) == 0 || m.rfind(truth.path() + ":", 0) == 0);
  }
}

void fuzz_gait(MemFile& file, bool require_gyro) {
  try {
    bool gyro = false;
    bool mag = false;
    const auto recs = telltale::cli::read_imu_csv(file.path(), require_gyro, &gyro, &mag);
    FUZZ_CHECK(!recs.empty());
    if (require_gyro) FUZZ_CHECK(gyro);
    for (const auto& r : recs) {
      FUZZ_CHECK(r.imu.acc_body_m_s2.allFinite());
      FUZZ_CHECK(gyro ? r.imu.gyro_body_rad_s.allFinite() : r.imu.gyro_body_rad_s.hasNaN());
      if (!mag) FUZZ_CHECK(r.mag_uT.hasNaN());
    }
  } catch (const CsvError& e) {
    check_error(e, file.path());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static MemFile file("fuzz_csv");
  static MemFile second("fuzz_csv_truth");
  static MemFile scratch("fuzz_csv_scratch");
  telltale::fuzz::Input in(data, size);
  const std::uint8_t format = in.byte();
  const std::string_view content = in.rest();
  if (format % 8 == 7) {
    fuzz_broad(file, second, content);
    return 0;
  }
  file.set(content);
  if (format % 8 >= 4) {
    // Program-level readers on the same bytes: gait_io (steps, pdr) and the strict variant.
    fuzz_gait(file, format % 8 == 5);
    return 0;
  }
  std::string time_column;
  const auto cols = columns_for(format, &time_column);
  const auto rows = read_checked(file.path(), cols, time_column);
  check_round_trip(scratch, cols, rows);
  return 0;
}
