#pragma once
/// \file
/// NMEA 0183 for the boat node: framing (address, checksum), the heading sentences `HDT`, `HDG`
/// and `HDM` from any talker, and the readers of a serial device or a UDP port. The GNSS
/// sentences are parsed in nmea_gnss.hpp on the same framing and readers.
///
/// Layers, each usable alone:
/// - frame_nmea(): one line -> talker, sentence type and fields, or the reason it is not a
///   sentence (checksum, address, characters, length). Never throws.
/// - parse_nmea_heading(): one line -> a heading or the reason it is not one. Never throws.
/// - NmeaLineAssembler: a byte stream (partial reads, CR, LF or CRLF, garbage between sentences,
///   over-long lines) -> complete lines starting with '$'. Fixed buffer, never grows.
/// - NmeaSerialReader / NmeaUdpReader: poll() a file descriptor, hand every line to a parser
///   (heading or GNSS) with its receive time, count what was skipped; stop() from any thread.
///
/// Decisions (NMEA 0183 leaves them to the receiver):
/// - Checksum: verified whenever "*hh" is present (hex, either case). A sentence WITHOUT a
///   checksum is rejected by default (`NmeaParseOptions::accept_missing_checksum = false`):
///   NMEA 0183 v2+ requires it on these sentences, and a corrupted digit in an unchecked heading
///   can look plausible enough to pass the fusion's consistency gate for a while. Old
///   instruments and some Wi-Fi bridges drop it: set the option for them; they are counted.
/// - HDG "x.x,d.d,E,v.v,W": magnetic = sensor heading + deviation (E +, W -), true = magnetic +
///   variation (E +, W -), both wrapped to [0, 360). With no deviation field the sensor heading
///   is taken as magnetic. With no variation field there is no true heading (`true_deg` NaN):
///   the node must then supply the variation (or fuse only true sources) — we never guess it.
/// - Headings must be finite numbers in [0, 360]; 360 reads as 0. "nan", "inf", signs on the
///   heading, empty heading fields, trailing junk in a field: malformed.
/// - A line longer than kNmeaMaxLine (NMEA allows 82 characters) is dropped whole.

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace telltale::sensors {

/// Longest line kept by the assembler, characters from '$' to before CR/LF. NMEA says 82 with
/// CRLF; a little slack for talkers that pad.
inline constexpr std::size_t kNmeaMaxLine = 120;

enum class NmeaSentence : std::uint8_t { kHdt, kHdg, kHdm };

struct NmeaHeading {
  std::array<char, 3> talker{};  ///< two letters and a NUL, e.g. "HE", "HC", "GP", "II"
  NmeaSentence sentence = NmeaSentence::kHdt;
  double true_deg = 0.0;       ///< true heading [0, 360), NaN if the sentence cannot give it
  double magnetic_deg = 0.0;   ///< magnetic heading [0, 360), NaN for HDT
  double deviation_deg = 0.0;  ///< HDG only, E positive, NaN if absent
  double variation_deg = 0.0;  ///< HDG only, E positive, NaN if absent
  bool had_checksum = false;
};

enum class NmeaStatus : std::uint8_t {
  kOk,
  kNotNmea,          ///< does not start with '$' + 5 address characters
  kUnsupported,      ///< a valid-looking sentence that is not HDT/HDG/HDM (GGA, RMC, ...)
  kBadChecksum,      ///< "*hh" present and wrong, or not two hex digits
  kMissingChecksum,  ///< no "*hh" and the options require one
  kMalformed,        ///< wrong field count, empty/garbled/non-finite/out-of-range numbers
  kTooLong,          ///< longer than kNmeaMaxLine
};

[[nodiscard]] const char* nmea_status_name(NmeaStatus s);

struct NmeaParseOptions {
  bool accept_missing_checksum = false;  ///< see the file comment
};

/// One framed sentence: views into the line handed to frame_nmea().
struct NmeaFrame {
  std::array<char, 3> talker{};  ///< two letters and a NUL
  std::string_view type;         ///< three letters: "RMC", "HDT", ...
  std::string_view fields;       ///< everything after "$TTSSS," up to '*' (may be empty)
  bool had_checksum = false;
};

/// Checks the address, the checksum, the characters and the length of one line (trailing CR/LF
/// allowed). kOk fills `out`; otherwise the reason. Never throws, never allocates.
[[nodiscard]] NmeaStatus frame_nmea(std::string_view line, const NmeaParseOptions& options,
                                    NmeaFrame& out);

/// Splits "a,b,c" into at most N fields; returns the field count (N + 1 if there are more).
template <std::size_t N>
std::size_t split_nmea_fields(std::string_view s, std::array<std::string_view, N>& out) {
  std::size_t n = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= s.size(); ++i) {
    if (i == s.size() || s[i] == ',') {
      if (n == N) return N + 1;
      out[n++] = s.substr(start, i - start);
      start = i + 1;
    }
  }
  return n;
}

/// Strict unsigned decimal: digits with at most one '.', nothing else ("nan", "1e3", "-2",
/// " 5" are all rejected: from_chars alone would accept "nan" and "inf").
[[nodiscard]] bool parse_nmea_number(std::string_view f, double& out);

struct NmeaParseResult {
  NmeaStatus status = NmeaStatus::kNotNmea;
  NmeaHeading heading{};  ///< valid when status == kOk
};

/// Parses one line (with or without trailing CR/LF). Never throws, never allocates.
[[nodiscard]] NmeaParseResult parse_nmea_heading(std::string_view line,
                                                 const NmeaParseOptions& options = {});

/// Splits a byte stream into lines that start with '$'. Bytes outside a sentence are counted as
/// garbage; a '$' inside a sentence restarts (the cut one is counted as truncated).
class NmeaLineAssembler {
 public:
  struct Stats {
    std::uint64_t lines = 0;
    std::uint64_t garbage_bytes = 0;
    std::uint64_t overlong = 0;
    std::uint64_t truncated = 0;
  };
  using LineCallback = std::function<void(std::string_view)>;

  /// Feeds bytes; calls `on_line` for every complete line (without CR/LF).
  void feed(const char* data, std::size_t size, const LineCallback& on_line);
  /// End of a record (a UDP datagram): a sentence without a line ending is complete too.
  void end_of_record(const LineCallback& on_line);
  [[nodiscard]] const Stats& stats() const { return stats_; }

 private:
  void finish(const LineCallback& on_line);
  std::array<char, kNmeaMaxLine> buf_{};
  std::size_t len_ = 0;
  bool in_line_ = false;
  bool overflow_ = false;
  Stats stats_;
};

/// What a reader saw, by outcome.
struct NmeaReaderStats {
  std::uint64_t bytes = 0;
  std::uint64_t accepted = 0;  ///< sentences the parser took (headings, GNSS sentences)
  std::uint64_t unsupported = 0;
  std::uint64_t bad_checksum = 0;
  std::uint64_t missing_checksum = 0;
  std::uint64_t malformed = 0;  ///< malformed, not NMEA, too long, truncated
  std::uint64_t garbage_bytes = 0;
};

using NmeaClock = std::chrono::steady_clock;
/// Called on the reader's thread for every heading, with the time its bytes were read.
using NmeaHeadingCallback = std::function<void(const NmeaHeading&, NmeaClock::time_point)>;
/// Called on the reader's thread for every line, with the time its bytes were read; returns
/// what the line was (kOk when taken), which the reader counts.
using NmeaLineHandler = std::function<NmeaStatus(std::string_view, NmeaClock::time_point)>;

/// Common poll loop of the readers (a file descriptor plus a self-pipe for stop()).
class NmeaStreamReader {
 public:
  NmeaStreamReader(const NmeaStreamReader&) = delete;
  NmeaStreamReader& operator=(const NmeaStreamReader&) = delete;
  virtual ~NmeaStreamReader();

  /// Waits up to timeout_ms for data, hands every line that came to `handler`. Returns false
  /// once stopped or when the device is gone (EOF, hang-up, read error).
  bool poll_lines(int timeout_ms, const NmeaLineHandler& handler);
  /// Headings: poll_lines with parse_nmea_heading, `cb` called for every heading.
  bool poll_once(int timeout_ms, const NmeaHeadingCallback& cb);
  /// Loops poll_once until stop() or the device is gone.
  void run(const NmeaHeadingCallback& cb);
  /// Thread-safe and async-signal-safe: makes run() return within one poll.
  void stop();
  [[nodiscard]] NmeaReaderStats stats() const;
  [[nodiscard]] const NmeaParseOptions& options() const { return options_; }

 protected:
  explicit NmeaStreamReader(NmeaParseOptions options);
  /// Takes ownership of fd (closed in the destructor). Throws std::system_error.
  void attach(int fd);
  /// Reads once from fd into the assembler; false at EOF/error.
  virtual bool read_available(const NmeaLineHandler& handler) = 0;
  void on_line(std::string_view line, NmeaClock::time_point t, const NmeaLineHandler& handler);
  /// Publishes the assembler's counters to the atomics stats() reads.
  void account_assembler();
  [[nodiscard]] int fd() const { return fd_; }
  NmeaLineAssembler assembler_;

 private:
  NmeaParseOptions options_;
  int fd_ = -1;
  int stop_pipe_[2] = {-1, -1};
  std::atomic<bool> stopped_{false};
  std::atomic<std::uint64_t> bytes_{0}, accepted_{0}, unsupported_{0}, bad_checksum_{0},
      missing_checksum_{0}, malformed_{0}, garbage_{0};
  std::uint64_t assembler_dropped_ = 0;  ///< overlong + truncated already added to malformed_

  friend class NmeaSerialReader;
  friend class NmeaUdpReader;
};

/// A serial device (or pseudo-terminal) in raw mode, 8N1, no flow control.
class NmeaSerialReader : public NmeaStreamReader {
 public:
  /// Opens and configures `device` at `baud` (4800, 9600, 19200, 38400, 57600, 115200, 230400).
  /// Throws std::system_error (no such device, not a tty) or std::invalid_argument (baud).
  NmeaSerialReader(const std::string& device, int baud = 4800, NmeaParseOptions options = {});

 private:
  bool read_available(const NmeaLineHandler& handler) override;
};

/// A UDP socket bound to `address:port` (port 0: the OS picks one, see port()). One or more
/// sentences per datagram; a datagram ends the last sentence even without CR/LF.
class NmeaUdpReader : public NmeaStreamReader {
 public:
  /// Throws std::system_error (bind failed) or std::invalid_argument (bad address).
  explicit NmeaUdpReader(const std::string& address = "127.0.0.1", std::uint16_t port = 0,
                         NmeaParseOptions options = {});
  [[nodiscard]] std::uint16_t port() const { return port_; }

 private:
  bool read_available(const NmeaLineHandler& handler) override;
  std::uint16_t port_ = 0;
};

}  // namespace telltale::sensors
