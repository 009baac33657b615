#pragma once
/// \file
/// GET /api/v1/sessions/{id}/manoeuvres[?format=csv][&wind_from_deg=N][&from=T]: the session's
/// tacks, gybes, bear-aways, round-ups and penalty turns (telltale/fusion/manoeuvres.hpp, every
/// metric defined there) from its fixes joined with the attitude (heel, pitch), a summary per kind
/// and the wind: the coach's (`wind_from_deg`), else the boat's wind instrument (the stored
/// readings of an imported log's MWV/MWD or VKX wind rows, their robust circular mean over the
/// stretch), else estimated from the tacks; when given either way, the estimate is reported
/// beside it with its error against the instrument (`wind.estimate_error_deg`). `from` (the fleet
/// view filling in a live session): only the manoeuvres with t0 from then, found in the data of the
/// 45 s before it on, with summary and wind of that stretch; `data_to_utc` says how far the data
/// went (a metric's window past it is not complete yet).

#include <httplib.h>

#include <cstdint>
#include <nlohmann/json.hpp>

#include "http_api.hpp"
#include "telltale/fusion/manoeuvres.hpp"

namespace telltale::shore {

void register_manoeuvre_routes(httplib::Server& server, ShoreContext& ctx);

/// One manoeuvre as the API lists it (`t_utc` its t0, at `t0_utc_ns`): the row of this endpoint
/// and the `manoeuvre` event of the live stream (manoeuvre_live.hpp), so both name every metric
/// alike.
[[nodiscard]] nlohmann::json manoeuvre_object(const fusion::Manoeuvre& m, std::uint64_t t0_utc_ns);

}  // namespace telltale::shore
