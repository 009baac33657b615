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
/// Every write is checked. A write that fails (disk full, I/O error) leaves no torn record: the
/// file is cut back to its last whole record and the records not written are held in memory
/// (bounded: `max_pending_bytes`, the oldest dropped first) and written again at the next
/// append or flush, so the file stays on the 96-byte grid. If records had to be dropped, the
/// log rolls to a new file at the next seq it holds. `health()` tells the node what to report.
/// The reader also resynchronises on a damaged file (a power cut mid-write, or a file an older
/// build left torn): it scans for the next record with a valid magic and CRC.
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
  std::size_t max_pending_bytes = 4u << 20;  ///< held while writes fail: ~29 min at 25 Hz
};

/// What the log could not do (all zero/empty when every record is on disk).
struct SessionLogHealth {
  std::uint64_t pending_records = 0;  ///< appended, not on disk yet (buffered, or held while
                                      ///< writes fail)
  std::uint64_t dropped_records = 0;  ///< given up: beyond max_pending_bytes while failing
  std::uint64_t write_errors = 0;     ///< failed write attempts since start
  std::string last_error;             ///< of the latest failed write, empty once writes succeed
  /// The latest write failed, or records were given up: what is held is at risk. Records merely
  /// buffered between two flushes are not a failure.
  [[nodiscard]] bool failing() const { return !last_error.empty() || dropped_records > 0; }
};

class SessionLog {
 public:
  /// Creates the directory if needed. Throws std::runtime_error if it cannot be written to (a
  /// read-only mount, no permission): a boat must not sail without a log. A directory on a full
  /// disk is accepted (writes are retried, see health()).
  explicit SessionLog(SessionLogConfig config);
  ~SessionLog();
  SessionLog(const SessionLog&) = delete;
  SessionLog& operator=(const SessionLog&) = delete;

  /// Appends one record (seq must be the previous + 1). Returns false while writes fail (disk
  /// full): the record is held in memory and written once the disk takes it again; the node
  /// reports health() in its status.
  [[nodiscard]] bool append(const LogRecord& record);
  /// Pushes buffered records to the OS (called about once a second and at shutdown). False if
  /// some could not be written (they stay held, see health()).
  bool flush();
  [[nodiscard]] std::uint64_t bytes_deleted() const { return bytes_deleted_; }
  [[nodiscard]] SessionLogHealth health() const;

 private:
  /// Writes the held records; false (and records the error) if some could not be written.
  bool write_pending();
  bool open_next(std::uint64_t first_seq);
  void enforce_limit();
  void fail(int err);

  SessionLogConfig config_;
  int fd_ = -1;
  std::filesystem::path current_;
  std::uint64_t file_first_seq_ = 0;
  std::uint64_t in_file_ = 0;           ///< whole records on disk in the current file
  std::vector<unsigned char> pending_;  ///< encoded records not on disk yet, contiguous seqs
  std::uint64_t pending_first_seq_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t write_errors_ = 0;
  std::string last_error_;
  std::uint64_t bytes_deleted_ = 0;
};

/// Reads records of one boot back by sequence number.
class SessionLogReader {
 public:
  SessionLogReader(std::filesystem::path dir, std::string boat_id, std::uint64_t boot_id);
  /// Records with first_seq <= seq <= last_seq that are on disk, in order (missing if deleted by
  /// the disk policy or corrupt: CRC checked). A file off the record grid (a torn record) is
  /// scanned for every intact record.
  [[nodiscard]] std::vector<LogRecord> read(std::uint64_t first_seq, std::uint64_t last_seq);
  /// The highest seq on disk for this run (0 if none), from the files' names and sizes (a file
  /// whose last record does not match is scanned).
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
