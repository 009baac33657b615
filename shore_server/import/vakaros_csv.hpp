#pragma once
/// \file
/// Vakaros Atlas CSV exports, both dialects in use:
/// - `timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim` with local time and its UTC
///   offset (`2026-02-08T11:56:40.049+0100`);
/// - the older `timestamp,latitude,longitude,sog_kts,cog,hdg_true,roll,pitch[,load_...]` whose time
///   has no offset: the import needs ImportOptions::utc_offset_s or local_offset_s (a named time
///   zone, summer time included), and is refused without one.
/// Columns are found by name (any case, any order, extra columns ignored); CRLF or LF; a UTF-8
/// byte order mark is skipped; blank rows and spreadsheet padding (rows of commas, trailing empty
/// cells) are passed over and counted. SOG in knots becomes m/s; heel/roll is + starboard down and
/// trim/pitch + bow up, as the contract's. Any other malformed row is an error naming its line.
/// Streaming: one line in memory (at most kMaxLine bytes).

#include "record.hpp"

namespace telltale::shore::import {

[[nodiscard]] ParseResult parse_vakaros_csv(std::istream& in, const ImportOptions& options,
                                            ImportSink& sink);

}  // namespace telltale::shore::import
