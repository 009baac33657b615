#pragma once
/// \file
/// POST /api/v1/imports?[boat=ID][&format=NAME][&tz=OFFSET][&heel_offset=DEG][&pitch_offset=DEG]
/// [&declination=DEG][&date=YYYY-MM-DD][&name=FILE] with the file as the body (coach and analyst; streamed to the
/// spool folder, at most HttpConfig::max_import_bytes): 202 {"id": N, "state": "running"}.
/// Without a boat, a file that names its device's serial (Velocitek VTK) goes to
/// `velocitek-SERIAL`; any other is a 400.
/// GET /api/v1/imports/{id}: state (running | done | failed), bytes read of bytes, format,
/// device, sessions, points, samples and fixes added, events, error, partial reason,
/// duplicate_of. GET /api/v1/imports?boat&session&limit: the imports, newest first (a session's
/// sources: `session=N`). `import_json` is the one JSON view of an import (routes and events).

#include <httplib.h>

#include <cstddef>
#include <nlohmann/json.hpp>

#include "http_api.hpp"
#include "import_service.hpp"

namespace telltale::shore {

void register_import_routes(httplib::Server& server, ShoreContext& ctx,
                            import::ImportService& imports, std::size_t max_import_bytes);

[[nodiscard]] nlohmann::json import_json(const import::ImportRecord& r);

}  // namespace telltale::shore
