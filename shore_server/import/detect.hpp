#pragma once
/// \file
/// Which log format a file is, from its first bytes (never from its name): text formats by
/// their header or first sentences, binary ones by their framing.
/// - GPX: a `<gpx` element in the head (after an XML declaration, comments, a BOM).
/// - Atlas CSV: a first non-blank line naming timestamp, latitude and longitude columns.
/// - NMEA log: most non-blank lines of the head are sentences (with or without a time stamp).
/// - VKX: a page header row (0xFF) then a known row key after its 7 bytes.
/// - VTK: a first record (u16 length) that decodes as a protobuf Record.

#include <optional>
#include <string_view>

#include "record.hpp"

namespace telltale::shore::import {

/// Bytes detect_format() wants to see (it works on fewer at the end of a small file).
inline constexpr std::size_t kDetectBytes = 4096;

[[nodiscard]] std::optional<Format> detect_format(std::string_view head);

}  // namespace telltale::shore::import
