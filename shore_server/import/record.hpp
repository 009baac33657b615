#pragma once
/// \file
/// What every log parser yields: points (time, position, speed, course, heading, heel, pitch, each
/// optional) and events (race timer, line ends, buttons), handed one at a time to an ImportSink so
/// that no parser holds a file in memory. Units and signs are the contract's (idl/README.md):
/// heel_deg > 0 starboard down, pitch_deg > 0 bow up, headings and courses true, clockwise from
/// north in [0, 360), SOG in m/s, time UTC in ns since 1970.

#include <cstdint>
#include <functional>
#include <istream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

namespace telltale::shore::import {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One instant of a log; a field the file does not carry is NaN.
struct ImportPoint {
  std::uint64_t t_utc_ns = 0;
  double lat_deg = kNaN;
  double lon_deg = kNaN;
  double sog_m_s = kNaN;
  double cog_deg = kNaN;      ///< true
  double heading_deg = kNaN;  ///< true (a magnetic one is corrected by the declination, else NaN)
  double heel_deg = kNaN;
  double pitch_deg = kNaN;
};

/// The true wind at one instant, as a wind instrument gave it, made true by
/// telltale/fusion/wind.hpp: the direction it blows from, clockwise from true north in [0, 360),
/// and its speed in m/s (NaN when the instrument gave none). `source` names what it came from:
/// "mwd", "mwd_magnetic", "mwv_true", "mwv_apparent" (NMEA), "vkx_apparent".
struct ImportWind {
  std::uint64_t t_utc_ns = 0;
  double from_deg = kNaN;
  double speed_m_s = kNaN;
  const char* source = "";
};

/// Something the sailor or the device marked: "timer_start", "race_start", "pin", ...
struct ImportEvent {
  std::uint64_t t_utc_ns = 0;
  std::string kind;
  std::string detail;  ///< free text (timer seconds, position), may be empty
};

/// The user's options for one file.
struct ImportOptions {
  /// Offset from UTC of local times without one (Atlas CSV's older dialect); nullopt: such a file
  /// is refused, never guessed.
  std::optional<std::int64_t> utc_offset_s;
  /// Else the offset of a time zone, given the local time (seconds since 1970 read as if local
  /// were UTC): time_zone.hpp's TimeZone::offset_at_local. Empty: none.
  std::function<std::int64_t(std::int64_t)> local_offset_s;
  double heel_offset_deg = 0.0;   ///< subtracted from every heel (the instrument's zero)
  double pitch_offset_deg = 0.0;  ///< subtracted from every pitch (Atlas trim reads ~+6 at rest)
  /// East positive; used for magnetic headings when the file states no declination. NaN: none.
  double declination_deg = kNaN;
  /// The UTC date (days since 1970) of an NMEA log that states none (no RMC or ZDA date and no
  /// time stamps): its times of day are taken on that date. nullopt: such a log is refused.
  std::optional<std::int64_t> date_days;
};

/// Receives what a parser reads, in file order.
class ImportSink {
 public:
  virtual ~ImportSink() = default;
  virtual void point(const ImportPoint& p) = 0;
  virtual void event(const ImportEvent& e) = 0;
  /// A wind instrument's reading (logs with one); ignored by default.
  virtual void wind(const ImportWind&) {}
  /// The device that wrote the file (model, serial), when the file says.
  virtual void device(std::string_view) {}
};

enum class ParseStatus : std::uint8_t {
  kOk,
  kPartial,  ///< a meaningful prefix was read (binary logs cut or with an unknown row)
  kError,    ///< nothing of the file may be kept
};

struct ParseResult {
  ParseStatus status = ParseStatus::kOk;
  std::string message;  ///< the error or the partial reason, naming the line or byte offset
  std::uint64_t points = 0;
  std::uint64_t events = 0;
  std::uint64_t skipped = 0;  ///< lines or records passed over (blank rows, foreign sentences)
};

enum class Format : std::uint8_t { kVakarosCsv, kVkx, kVtk, kNmea, kGpx };

[[nodiscard]] const char* format_name(Format f);
[[nodiscard]] std::optional<Format> parse_format(std::string_view name);

/// Parses `in` as `format`. Never throws on bad input: the result says what was wrong.
[[nodiscard]] ParseResult parse_log(Format format, std::istream& in, const ImportOptions& options,
                                    ImportSink& sink);

// --- helpers shared by the parsers --------------------------------------------------------

/// "+01:00", "-0700", "+05", "Z", "UTC": seconds east of UTC; nullopt when not an offset.
[[nodiscard]] std::optional<std::int64_t> parse_utc_offset(std::string_view s);

/// ISO 8601 date and time "YYYY-MM-DD[T ]hh:mm:ss[.fff][Z|+hh:mm|+hhmm]". Without a zone the
/// time is local and `default_offset_s` applies; nullopt when it is not such a time, or has no
/// zone and no default.
[[nodiscard]] std::optional<std::uint64_t> parse_iso_time(std::string_view s,
                                                          std::optional<std::int64_t> default_offset_s,
                                                          bool* had_zone = nullptr);

/// Days since 1970-01-01 of a proleptic Gregorian date; nullopt when the date does not exist.
[[nodiscard]] std::optional<std::int64_t> days_from_civil(int year, int month, int day);

/// Strict signed decimal (digits, one '.', optional sign and exponent; no "nan"/"inf"); nullopt
/// otherwise. Leading and trailing blanks allowed.
[[nodiscard]] std::optional<double> parse_decimal(std::string_view s);

/// Heel, pitch and heading (deg, the contract's signs) from a unit quaternion w, x, y, z that
/// turns the body frame FRD into NED (x north, y east, z down). Non-finite or zero: all NaN.
struct Euler {
  double heel_deg = kNaN;
  double pitch_deg = kNaN;
  double heading_deg = kNaN;
};
[[nodiscard]] Euler euler_from_ned_quaternion(double w, double x, double y, double z);

/// Applies the zero offsets of `options` to a point's heel and pitch.
void apply_offsets(const ImportOptions& options, ImportPoint& p);

}  // namespace telltale::shore::import
