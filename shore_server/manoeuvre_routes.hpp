#pragma once
/// \file
/// GET /api/v1/sessions/{id}/manoeuvres[?format=csv][&wind_from_deg=N]: the session's tacks,
/// gybes, bear-aways, round-ups and penalty turns (telltale/fusion/manoeuvres.hpp, every metric
/// defined there) from its fixes joined with the attitude (heel, pitch), a summary per kind and
/// the wind (estimated from the tacks unless given).

#include <httplib.h>

#include "http_api.hpp"

namespace telltale::shore {

void register_manoeuvre_routes(httplib::Server& server, ShoreContext& ctx);

}  // namespace telltale::shore
