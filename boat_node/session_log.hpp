#pragma once
/// \file
/// The boat's session log: every published attitude sample appended to disk, so nothing is lost
/// while the shore is unreachable and the shore can be refilled later (backfill).
///
/// Format: fixed 96-byte little-endian records with a CRC-32 each, in files
/// `<dir>/<boat>-<boot_id>-<first_seq>.tlog` of at most `records_per_file` records. Disk policy:
/// the total size of all `.tlog` files in the directory is kept under `max_bytes` by deleting the
/// oldest files first (never the one being written). At 25 Hz a record stream is 8.6 MB per hour,
/// so the default 1 GiB holds about 5 days of sailing.
///
/// Not thread-safe: the sensor loop appends; the backfill thread reads through its own
/// `SessionLogReader` (files are only appended to, so a reader sees complete records).

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace telltale::boat {

struct LogRecord {
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;
  double heel_deg = 0;
  double pitch_deg = 0;
  double heading_deg = 0;
  double heel_rate_deg_s = 0;
  double pitch_rate_deg_s = 0;
  double yaw_rate_deg_s = 0;
  float accel_weight = 0;
  float quality = 0;
  std::uint8_t leds[4] = {0, 0, 0, 0};
  std::uint8_t led_count = 0;
  std::uint8_t level = 0;
};

struct SessionLogConfig {
  std::filesystem::path dir;
  std::string boat_id;
  std::uint64_t boot_id = 0;
  std::uint64_t records_per_file = 100000;  ///< about 67 min at 25 Hz
  std::uint64_t max_bytes = 1ULL << 30;
};

class SessionLog {
 public:
  /// Creates the directory if needed. Throws std::runtime_error if it cannot be written.
  explicit SessionLog(SessionLogConfig config);
  ~SessionLog();
  SessionLog(const SessionLog&) = delete;
  SessionLog& operator=(const SessionLog&) = delete;

  /// Appends one record (seq must be the previous + 1). Returns false on a write error (disk
  /// full): the sample is then only on the wire, and the node reports it in its status.
  [[nodiscard]] bool append(const LogRecord& record);
  /// Pushes buffered records to the OS (called about once a second and at shutdown).
  void flush();
  [[nodiscard]] std::uint64_t bytes_deleted() const { return bytes_deleted_; }

 private:
  void open_next(std::uint64_t first_seq);
  void enforce_limit();

  SessionLogConfig config_;
  std::FILE* file_ = nullptr;
  std::filesystem::path current_;
  std::uint64_t in_file_ = 0;
  std::uint64_t bytes_deleted_ = 0;
};

/// Reads records of one boot back by sequence number.
class SessionLogReader {
 public:
  SessionLogReader(std::filesystem::path dir, std::string boat_id, std::uint64_t boot_id);
  /// Records with first_seq <= seq <= last_seq that are on disk, in order (missing if deleted by
  /// the disk policy or corrupt: CRC checked).
  [[nodiscard]] std::vector<LogRecord> read(std::uint64_t first_seq, std::uint64_t last_seq);
  /// The highest seq on disk for this run (0 if none), from the newest file's name and size.
  [[nodiscard]] std::uint64_t last_seq() const;

 private:
  std::filesystem::path dir_;
  std::string prefix_;
};

/// Earlier runs of this boat in `dir` whose log the shore has not confirmed in full (no
/// `<boat>-<boot>.delivered` marker) and that were written to within `max_age`, oldest first;
/// `current_boot` excluded. Markers of runs whose files the disk policy has deleted are removed.
[[nodiscard]] std::vector<std::uint64_t> undelivered_runs(const std::filesystem::path& dir,
                                                          const std::string& boat_id,
                                                          std::uint64_t current_boot,
                                                          std::chrono::hours max_age);
/// Records that the shore holds the run (or all of it the log still has): not offered again.
void mark_delivered(const std::filesystem::path& dir, const std::string& boat_id,
                    std::uint64_t boot_id);

/// Encodes/decodes one record (exposed for tests).
inline constexpr std::size_t kLogRecordBytes = 96;
void encode_record(const LogRecord& r, unsigned char* out);
[[nodiscard]] std::optional<LogRecord> decode_record(const unsigned char* in);

}  // namespace telltale::boat
