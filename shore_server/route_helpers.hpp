#pragma once
/// \file
/// What every REST route does first: who is asking, may they see this boat, are the parameters
/// the route's own. Shared by the route files (rest_routes.cpp, track_routes.cpp).

#include <httplib.h>

#include <algorithm>
#include <initializer_list>
#include <optional>
#include <string>

#include "http_api.hpp"
#include "query.hpp"

namespace telltale::shore {

inline Principal who(const ShoreContext& ctx, const httplib::Request& req) {
  return authenticate(ctx.tokens, req.get_header_value("Authorization"),
                      req.get_header_value("Cookie"));
}

inline void require_coach(const Principal& p) {
  if (p.role != Role::kCoach) throw HttpError(403, "only a coach may do this");
}

inline void require_boat(const Principal& p, const std::string& boat_id) {
  if (p.role == Role::kAthlete && p.boat_id != boat_id)
    throw HttpError(403, "an athlete sees only their own boat");
}

/// The query parameters a route accepts; any other is a 400 (a typo must not be ignored).
inline void allow_params(const httplib::Request& req, std::initializer_list<const char*> allowed) {
  for (const auto& kv : req.params) {
    const std::string& name = kv.first;  // a plain name: clang 14 cannot capture a binding
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return name == a; }))
      throw HttpError(400, "unknown parameter '" + name + "'");
    if (req.get_param_value_count(name) > 1)
      throw HttpError(400, "parameter '" + name + "' given more than once");
  }
}

inline const std::string* param(const httplib::Request& req, const char* name) {
  auto it = req.params.find(name);
  return it == req.params.end() ? nullptr : &it->second;
}

/// The `boat` query filter as the caller may use it: checked, and an athlete's own boat whether
/// given or not (403 for another boat). Nothing: every boat.
inline std::optional<std::string> boat_filter(const httplib::Request& req, const Principal& p) {
  std::optional<std::string> boat;
  if (const std::string* b = param(req, "boat")) {
    if (!valid_id(*b)) throw HttpError(400, "boat id must be 1-32 of [A-Za-z0-9_-]");
    boat = *b;
  }
  if (p.role == Role::kAthlete) {
    if (boat && *boat != p.boat_id) throw HttpError(403, "an athlete sees only their own boat");
    boat = p.boat_id;
  }
  return boat;
}

inline std::string path_id(const httplib::Request& req, const char* what) {
  const std::string id = req.matches[1];
  if (!valid_id(id)) throw HttpError(400, std::string(what) + " id must be 1-32 of [A-Za-z0-9_-]");
  return id;
}

inline std::int64_t path_number(const httplib::Request& req, const char* what) {
  const auto n = parse_int(req.matches[1], 1, INT64_MAX);
  if (!n) throw HttpError(400, std::string(what) + " id must be a positive integer");
  return *n;
}

}  // namespace telltale::shore
