#pragma once
/// \file
/// Vakaros VKX binary logs (the vendor's public format description, version 1.4): a sequence of
/// rows, each a 1-byte key and a payload whose size the key fixes (rows carry no length), little
/// endian throughout. Read: page header 0xFF and terminator 0xFE, position/velocity/orientation
/// 0x02 (Unix ms, lat/lon 1e-7 deg, SOG m/s, COG rad, altitude, quaternion w x y z of the body in
/// true NED -> heel, pitch, heading), declination 0x03, race timer 0x04 and line ends 0x05
/// (events), shift angle 0x06, configuration 0x08, wind 0x0A (apparent, from a Calypso sensor:
/// made true with the last 0x02 row's heading and velocity when at most 1 s older), speed
/// through water 0x0B, depth 0x0C, load 0x0F, temperature 0x10, and the internal rows 0x01,
/// 0x07, 0x0E, 0x20, 0x21 (sizes only). An unknown key stops the parse: without a length the rest
/// cannot be framed. What came before it (and before a row cut by the end of the file) is kept and
/// the result is kPartial with the reason and byte offset. Streaming: one row in memory.

#include "record.hpp"

namespace telltale::shore::import {

[[nodiscard]] ParseResult parse_vkx(std::istream& in, const ImportOptions& options,
                                    ImportSink& sink);

/// Payload size of a row key, or -1 for a key the description does not list.
[[nodiscard]] int vkx_payload_size(unsigned key);

}  // namespace telltale::shore::import
