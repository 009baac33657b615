#pragma once
/// \file
/// NMEA 0183 GNSS sentences: RMC, GGA, VTG, GSA and GNS from any talker (GP, GN, GL, GA, GB, II,
/// ...), on the framing of nmea.hpp, and the assembler that merges one receiver epoch (the burst
/// of sentences the receiver sends for one fix) into one GnssReading.
///
/// Decisions (NMEA 0183 leaves them to the receiver):
/// - A checksum is required, as for the headings (a corrupted digit in a position is a plausible
///   position).
/// - Every numeric field is a strict decimal (nmea.hpp); latitude "ddmm.mmmm" with minutes < 60
///   and degrees <= 90, longitude "dddmm.mmmm" with degrees <= 180, N/S/E/W required with them.
/// - A sentence that says "no fix" (RMC status V, GGA quality 0, GSA mode 1, GNS / RMC / VTG mode
///   indicator N) is parsed and makes the epoch a no-fix one; it is never an error.
/// - Speed: knots (RMC, VTG field 5) or km/h (VTG field 7), turned into m/s; RMC wins over VTG.
/// - Epochs: a sentence with a time of day opens a new epoch when its time differs from the open
///   one's; sentences without one (VTG, GSA) join the open epoch. The open epoch is emitted when
///   the next one opens or when the line has been quiet for `quiet_s` (the burst is over).

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "nmea.hpp"

namespace telltale::sensors {

enum class GnssSentence : std::uint8_t { kRmc, kGga, kVtg, kGsa, kGns };

/// One parsed GNSS sentence. Absent fields are NaN / -1.
struct NmeaGnss {
  GnssSentence sentence = GnssSentence::kRmc;
  std::array<char, 3> talker{};
  double time_of_day_s = 0.0;  ///< UTC seconds since midnight; NaN when absent (VTG, GSA)
  int date_ddmmyy = -1;        ///< RMC only
  double lat_deg = 0.0;        ///< NaN when absent
  double lon_deg = 0.0;
  double sog_m_s = 0.0;        ///< NaN when absent
  double cog_deg = 0.0;        ///< true course, NaN when absent
  bool no_fix = false;         ///< the sentence says there is no fix
  int gga_quality = -1;        ///< GGA 0..8
  int gsa_mode = -1;           ///< GSA 1 (none), 2 (2-D), 3 (3-D)
  bool differential = false;   ///< GGA quality 2/4/5, or mode indicator D/R/F
  int satellites = -1;
  double hdop = 0.0;           ///< NaN when absent
};

struct NmeaGnssResult {
  NmeaStatus status = NmeaStatus::kNotNmea;
  NmeaGnss gnss{};
};

/// Parses one line. kUnsupported for any other sentence. Never throws, never allocates.
[[nodiscard]] NmeaGnssResult parse_nmea_gnss(std::string_view line,
                                             const NmeaParseOptions& options = {});

enum class GnssFixKind : std::uint8_t { kNone, k2D, k3D, kDgnss };

/// One receiver epoch, merged from its sentences: what the gate and the wire take.
struct GnssReading {
  double lat_deg = 0.0;          ///< NaN without a fix
  double lon_deg = 0.0;
  double sog_m_s = 0.0;          ///< NaN when the receiver gave none
  double cog_deg = 0.0;          ///< NaN when the receiver gave none
  GnssFixKind fix = GnssFixKind::kNone;
  int satellites = 0;            ///< 0 when unknown
  double hdop = 0.0;             ///< NaN when unknown
  double time_of_day_s = 0.0;    ///< UTC seconds since midnight; NaN when unknown
  int date_ddmmyy = -1;          ///< -1 when no RMC gave it
  std::uint64_t utc_ns = 0;      ///< full UTC time when the source gives it (gpsd); 0 otherwise
};

/// Merges the sentences of one epoch. Not thread-safe; one per reader.
class GnssEpochAssembler {
 public:
  explicit GnssEpochAssembler(double quiet_s = 0.025) : quiet_s_(quiet_s) {}
  /// Adds a sentence received at `t_s` (any monotonic clock). Returns the previous epoch when
  /// this sentence opens a new one.
  std::optional<GnssReading> add(const NmeaGnss& g, double t_s);
  /// Returns the open epoch when nothing came for quiet_s before `t_s`.
  std::optional<GnssReading> flush_if_quiet(double t_s);

 private:
  [[nodiscard]] GnssReading merged() const;
  void reset();
  double quiet_s_;
  bool open_ = false;
  double last_t_s_ = 0.0;
  double tod_s_ = 0.0;
  int date_ = -1;
  double lat_ = 0.0, lon_ = 0.0, sog_ = 0.0, cog_ = 0.0, hdop_ = 0.0;
  bool have_pos_ = false, have_rmc_speed_ = false, no_fix_ = false, differential_ = false;
  int quality_ = -1, gsa_mode_ = -1, sats_ = -1;
};

}  // namespace telltale::sensors
