// libFuzzer target: what the REST API parses from a request (shore_server): query values (times,
// integers, ids, ranges), the alarm rules body of PUT /api/v1/alarms/rules, and the token from the
// Authorization and Cookie headers (login, every authenticated route). The first byte picks which.
//
// Invariants beyond "no crash": a parsed time lies in 1970..2262 and round-trips through the ISO
// form the API prints (to its milliseconds) and through epoch seconds exactly; a parsed integer is
// in its bounds and prints back to the same text (modulo a leading '+' or zeros, which must not
// parse); bad input is an HttpError with a 4xx status and nothing else; accepted rules are valid,
// have distinct ids and survive rule_object -> rule_from_json unchanged; a token is always a part
// of the header it came from.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "auth.hpp"
#include "fuzz_support.hpp"
#include "json_views.hpp"
#include "query.hpp"

namespace {

using telltale::shore::HttpError;

void check_time(const std::string& text) {
  const auto t = telltale::shore::parse_time_ns(text);
  if (!t) return;
  FUZZ_CHECK(*t <= 9'200'000'000'999'999'999ULL);
  // The ISO form the API prints (milliseconds) parses back to the time truncated to ms.
  const std::string iso = telltale::shore::iso8601(*t);
  const auto back = telltale::shore::parse_time_ns(iso);
  FUZZ_CHECK(back.has_value() && *back == *t / 1'000'000 * 1'000'000);
  // Epoch seconds with all nine decimals are exact.
  char epoch[40];
  std::snprintf(epoch, sizeof epoch, "%llu.%09llu",
                static_cast<unsigned long long>(*t / 1'000'000'000),
                static_cast<unsigned long long>(*t % 1'000'000'000));
  const auto exact = telltale::shore::parse_time_ns(epoch);
  FUZZ_CHECK(exact.has_value() && *exact == *t);
}

void check_int(telltale::fuzz::Input& in, const std::string& text) {
  const auto lo = static_cast<std::int64_t>(in.u64());
  const auto hi = static_cast<std::int64_t>(in.u64());
  const auto v = telltale::shore::parse_int(text, lo, hi);
  if (!v) return;
  FUZZ_CHECK(lo <= *v && *v <= hi);
  FUZZ_CHECK(text == std::to_string(*v) ||
             text.find_first_not_of("-0123456789") == std::string::npos);  // leading zeros only
}

void check_id(const std::string& text) {
  if (!telltale::shore::valid_id(text)) return;
  FUZZ_CHECK(!text.empty() && text.size() <= 32);
  FUZZ_CHECK(
      text.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") ==
      std::string::npos);
}

void check_range(const std::string& text) {
  // "from" and "to" separated by a NUL; a missing half is an absent parameter.
  const std::size_t nul = text.find('\0');
  const std::string from = text.substr(0, nul);
  const std::string to = nul == std::string::npos ? std::string() : text.substr(nul + 1);
  const std::string* f = from.empty() ? nullptr : &from;
  const std::string* t = nul == std::string::npos ? nullptr : &to;
  try {
    const auto r = telltale::shore::parse_range(f, t);
    FUZZ_CHECK(r.from_ns <= r.to_ns);
    if (!f) FUZZ_CHECK(r.from_ns == 0);
    if (!t) FUZZ_CHECK(r.to_ns == UINT64_MAX);
  } catch (const HttpError& e) {
    FUZZ_CHECK(e.status() == 400);
  }
}

void check_rules(const std::string& body) {
  try {
    const auto rules = telltale::shore::rules_from_body(body);
    FUZZ_CHECK(rules.size() <= telltale::shore::kMaxRules);
    for (std::size_t i = 0; i < rules.size(); ++i) {
      const auto& r = rules[i];
      FUZZ_CHECK(r.validate().empty());
      for (std::size_t k = 0; k < i; ++k) FUZZ_CHECK(rules[k].id != r.id);
      // What GET /api/v1/alarms/rules prints is what PUT accepts, unchanged.
      const auto again = telltale::shore::rule_from_json(telltale::shore::rule_object(r));
      FUZZ_CHECK(again.id == r.id && again.scope == r.scope && again.quantity == r.quantity &&
                 again.min_deg == r.min_deg && again.max_deg == r.max_deg &&
                 again.hold_s == r.hold_s && again.hysteresis_deg == r.hysteresis_deg &&
                 again.level == r.level && again.enabled == r.enabled);
    }
  } catch (const HttpError& e) {
    FUZZ_CHECK(e.status() == 400);
    FUZZ_CHECK(std::string(e.what()).size() > 0);
  }
}

void check_token(const std::string& text) {
  const std::size_t nul = text.find('\0');
  const std::string authorization = text.substr(0, nul);
  const std::string cookie = nul == std::string::npos ? std::string() : text.substr(nul + 1);
  const std::string token = telltale::shore::token_from_headers(authorization, cookie);
  if (authorization.size() > 7 && authorization.compare(0, 7, "Bearer ") == 0) {
    FUZZ_CHECK(token == authorization.substr(7));
  } else if (!token.empty()) {
    FUZZ_CHECK(cookie.find("telltale_token=" + token) != std::string::npos);
    FUZZ_CHECK(token.find(';') == std::string::npos);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  telltale::fuzz::Input in(data, size);
  const std::uint8_t which = in.byte();
  switch (which % 6) {
    case 0:
      check_time(std::string(in.rest()));
      break;
    case 1: {
      telltale::fuzz::Input bounds(data, size);
      (void)bounds.byte();
      const std::string text(in.size() > 16 ? in.rest().substr(16) : std::string_view());
      check_int(bounds, text);
      break;
    }
    case 2:
      check_id(std::string(in.rest()));
      break;
    case 3:
      check_range(std::string(in.rest()));
      break;
    case 4:
      check_rules(std::string(in.rest()));
      break;
    default:
      check_token(std::string(in.rest()));
      break;
  }
  return 0;
}
