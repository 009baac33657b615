#pragma once
/// \file
/// The boat's session log: every published attitude sample and every published GNSS fix appended
/// to disk, so nothing is lost while the shore is unreachable and the shore can be refilled later
/// (backfill).
///
/// One machinery, two record kinds: a codec per kind (AttitudeCodec, FixCodec) fills the body of
/// a fixed 96-byte little-endian frame (magic, CRC-32, body) and names the kind's magic and file
/// suffix; the log, the reader, the run bookkeeping and the backfill (backfill.hpp) are the same
/// code over either. Files: `<dir>/<boat>-<boot_id>-<first_seq>.tlog` (attitude) and `.tfix`
/// (fixes) of at most `records_per_file` records. A fix fills 70 of the 96 bytes: one frame size
/// keeps one grid, one torn-record scan and one fuzzed decoder, for 26 bytes per fix (1 MB an
/// hour at 10 Hz). Each kind's frames carry their own magic, so a fix file misread as attitude
/// (or the reverse) decodes to nothing rather than to wrong samples.
///
/// Disk policy: one budget over both kinds. The total size of all `.tlog` and `.tfix` files in the
/// directory is kept under `max_bytes` by deleting the oldest files first, whatever their kind
/// (never a file this run is still writing): a day of positions is worth as much as a day of
/// heel, and two budgets would each have to be sized for the worst case. At 25 Hz attitude and
/// 10 Hz fixes the log grows by 12.1 MB per hour, so the default 1 GiB holds about 3.7 days of
/// sailing.
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

/// One attitude sample as published (BoatAttitude without the ids).
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

/// One GNSS fix as published (BoatFix without the ids).
struct FixRecord {
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;
  std::uint64_t gnss_utc_ns = 0;
  double lat_deg = 0;
  double lon_deg = 0;
  double sog_m_s = 0;
  double cog_deg = 0;
  std::uint8_t fix = 0;  ///< telltale::msg::FixKind
  std::uint8_t satellites = 0;
  float hdop = 0;
};

/// Every frame on disk: magic (4), CRC-32 of the body (4), body (88).
inline constexpr std::size_t kLogRecordBytes = 96;
inline constexpr std::size_t kLogHeaderBytes = 8;

/// How an attitude sample fills a frame's body.
struct AttitudeCodec {
  using Record = LogRecord;
  static constexpr std::uint32_t kMagic = 0x544c4c54;  // "TLLT"
  static constexpr const char* kSuffix = ".tlog";
  static constexpr const char* kDelivered = ".delivered";  ///< the shore has the run
  static void encode(const Record& r, unsigned char* body);
  static Record decode(const unsigned char* body);
};

/// How a GNSS fix fills a frame's body.
struct FixCodec {
  using Record = FixRecord;
  static constexpr std::uint32_t kMagic = 0x58464c54;  // "TLFX"
  static constexpr const char* kSuffix = ".tfix";
  static constexpr const char* kDelivered = ".fixes-delivered";
  static void encode(const Record& r, unsigned char* body);
  static Record decode(const unsigned char* body);
};

struct SessionLogConfig {
  std::filesystem::path dir;
  std::string boat_id;
  std::uint64_t boot_id = 0;
  std::uint64_t records_per_file = 100000;   ///< about 67 min at 25 Hz
  std::uint64_t max_bytes = 1ULL << 30;      ///< over the files of both kinds
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

template <class Codec>
class BasicSessionLog {
 public:
  using Record = typename Codec::Record;
  /// Creates the directory if needed. Throws std::runtime_error if it cannot be written to (a
  /// read-only mount, no permission): a boat must not sail without a log. A directory on a full
  /// disk is accepted (writes are retried, see health()).
  explicit BasicSessionLog(SessionLogConfig config);
  ~BasicSessionLog();
  BasicSessionLog(const BasicSessionLog&) = delete;
  BasicSessionLog& operator=(const BasicSessionLog&) = delete;

  /// Appends one record (seq must be the previous + 1). Returns false while writes fail (disk
  /// full): the record is held in memory and written once the disk takes it again; the node
  /// reports health() in its status.
  [[nodiscard]] bool append(const Record& record);
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
template <class Codec>
class BasicSessionLogReader {
 public:
  using Record = typename Codec::Record;
  BasicSessionLogReader(std::filesystem::path dir, std::string boat_id, std::uint64_t boot_id);
  /// Records with first_seq <= seq <= last_seq that are on disk, in order (missing if deleted by
  /// the disk policy or corrupt: CRC checked). A file off the record grid (a torn record) is
  /// scanned for every intact record.
  [[nodiscard]] std::vector<Record> read(std::uint64_t first_seq, std::uint64_t last_seq);
  /// The highest seq on disk for this run (0 if none), from the files' names and sizes (a file
  /// whose last record does not match is scanned).
  [[nodiscard]] std::uint64_t last_seq() const;

 private:
  std::filesystem::path dir_;
  std::string prefix_;
};

using SessionLog = BasicSessionLog<AttitudeCodec>;
using FixLog = BasicSessionLog<FixCodec>;
using SessionLogReader = BasicSessionLogReader<AttitudeCodec>;
using FixLogReader = BasicSessionLogReader<FixCodec>;

/// Earlier runs of this boat in `dir` whose log of this kind the shore has not confirmed in full
/// (no `<boat>-<boot>` + Codec::kDelivered marker) and that were written to within `max_age`,
/// oldest first; `current_boot` excluded. Markers of runs whose files the disk policy has deleted
/// are removed. Each kind is delivered and confirmed on its own (its own topic and receipts).
template <class Codec = AttitudeCodec>
[[nodiscard]] std::vector<std::uint64_t> undelivered_runs(const std::filesystem::path& dir,
                                                          const std::string& boat_id,
                                                          std::uint64_t current_boot,
                                                          std::chrono::hours max_age);
/// Records that the shore holds the run's records of this kind (or all the log still has): not
/// offered again.
template <class Codec = AttitudeCodec>
void mark_delivered(const std::filesystem::path& dir, const std::string& boat_id,
                    std::uint64_t boot_id);

/// Encodes/decodes one frame (exposed for tests and the fuzzer): a frame of the other kind, or
/// one whose CRC does not match, decodes to nothing.
void encode_record(const LogRecord& r, unsigned char* out);
void encode_record(const FixRecord& r, unsigned char* out);
[[nodiscard]] std::optional<LogRecord> decode_record(const unsigned char* in);
[[nodiscard]] std::optional<FixRecord> decode_fix_record(const unsigned char* in);

}  // namespace telltale::boat
