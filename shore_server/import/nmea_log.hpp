#pragma once
/// \file
/// NMEA 0183 logs: one sentence per line, with or without a time stamp before it (an ISO 8601
/// time or Unix seconds/milliseconds, then a blank or ';'), including Signal K's multiplexed log
/// `ms;N;sentence`. The framing, checksum and the RMC/GGA/VTG/GNS and HDG/HDT/HDM parsers are the
/// boat node's (boat_node/sensors/nmea*.hpp); GLL, ZDA and XDR are read here. A checksum is
/// checked when present and not required: logs are often written by tools that drop it.
///
/// - Position and time: RMC (date), GGA, GLL, GNS; ZDA gives the date too. The sentences of one
///   receiver epoch (one time of day) make one point; its date comes from RMC/ZDA, else from the
///   line's time stamp, else from ImportOptions::date_days. Points before any date is known are
///   skipped (counted).
/// - Speed and course: RMC, VTG. Heading: HDT, HDG (true when it states the variation), HDM
///   (magnetic: made true with ImportOptions::declination_deg, else left out).
/// - Heel and pitch: XDR angle transducers named ROLL or HEEL (+ starboard down) and PTCH, PITCH
///   or TRIM (+ bow up), any case. Each value is attached once, to the epoch it came in (or the
///   next).
/// - Wind: MWD (a true direction; a magnetic one with the declination), MWV T (the instrument's
///   true angle off the bow, turned by the epoch's heading, else its COG) and MWV R (apparent,
///   made true with the boat's velocity), read by the boat node's parser
///   (boat_node/sensors/nmea_wind.hpp) and made true by telltale/fusion/wind.hpp; one per
///   epoch, the best kind in that order. MWV with status V, or MWD with a speed and no direction: skipped.
/// - Lines that are not sentences, fail their checksum or do not parse are skipped and counted;
///   the file is an error only if no point at all came out of it.
/// Streaming: one line in memory (longer than 1 KB: skipped).

#include "record.hpp"

namespace telltale::shore::import {

[[nodiscard]] ParseResult parse_nmea_log(std::istream& in, const ImportOptions& options,
                                         ImportSink& sink);

/// True if `line` looks like a log line this parser takes (for detection).
[[nodiscard]] bool looks_like_nmea_line(std::string_view line);

}  // namespace telltale::shore::import
