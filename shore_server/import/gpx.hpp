#pragma once
/// \file
/// GPX 1.0 and 1.1 tracks: every `trkpt` (lat, lon attributes; `time`) with its speed and course
/// where the file has them: GPX 1.0's `speed` (m/s) and `course` (deg true), the Garmin
/// TrackPointExtension's (v2) `speed` and `course`, and Telltale's own export
/// (`urn:telltale:gpx:1`: heel_deg, pitch_deg, sog_m_s, cog_deg), so a Telltale GPX reads back
/// whole. Elements are matched by local name, whatever their namespace prefix. A time without a
/// zone is UTC, as GPX requires, unless ImportOptions::utc_offset_s says otherwise. The root's
/// `creator` names the device.
///
/// A small streaming scanner of our own, not a full XML parser: tags, attributes, text,
/// comments, processing instructions and CDATA; one tag or one text run (at most 4 KB) in memory.
/// A track point without a valid position or time, or a file that ends inside an element, is an
/// error naming the line.

#include "record.hpp"

namespace telltale::shore::import {

[[nodiscard]] ParseResult parse_gpx(std::istream& in, const ImportOptions& options,
                                    ImportSink& sink);

}  // namespace telltale::shore::import
