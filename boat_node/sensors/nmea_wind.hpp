#pragma once
/// \file
/// NMEA 0183 wind sentences, from any talker (WI, II, ...):
///   MWV  angle, R|T, speed, unit (K km/h, M m/s, N knots, S mph), status A|V
///        R: apparent, off the bow; T: the instrument's true angle, off the bow
///   MWD  true direction, T, magnetic direction, M, knots, N, m/s, M
/// One line -> a reading (telltale/fusion/wind.hpp makes it the true wind) or why it is none:
/// kUnsupported for other sentences, kMalformed for a garbled field, a status V, an MWV R without
/// a speed (the speed is needed to take the boat's motion out) or an MWD with a speed and no
/// direction. Never throws.

#include <string_view>

#include "nmea.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::sensors {

struct NmeaWindResult {
  NmeaStatus status = NmeaStatus::kNotNmea;
  fusion::WindReading reading;  ///< valid when status == kOk
};

[[nodiscard]] NmeaWindResult parse_nmea_wind(std::string_view line,
                                             const NmeaParseOptions& options = {});

}  // namespace telltale::sensors
