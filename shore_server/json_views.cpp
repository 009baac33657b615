#include "json_views.hpp"

#include <charconv>
#include <cmath>
#include <ctime>
#include <set>

#include "query.hpp"
#include "telltale.h"

namespace telltale::shore {

using nlohmann::json;

std::string iso8601(std::uint64_t t_utc_ns) {
  const auto secs = static_cast<std::time_t>(t_utc_ns / 1000000000ULL);
  const auto ms = static_cast<unsigned>((t_utc_ns / 1000000ULL) % 1000ULL);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03uZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
  return buf;
}

std::string to_json_text(const json& j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

void append_json_number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  // 32 characters hold every double's shortest form (at most 24), so ec is never an error.
  out.append(buf, ec == std::errc() ? end : buf);
}

json boat_problems(const BoatView& v) {
  json out = json::array();
  const auto add = [&](const char* code, const std::string& text) {
    out.push_back({{"code", code}, {"text", text}});
  };
  const std::uint32_t health = v.status ? v.status->sensor_health : 0;
  // The log first: a boat whose log cannot write loses for good what the link drops meanwhile.
  if (health & msg::SENSOR_LOG_FAILING) add("log_failing", v.status->health_text);
  if (v.duplicate_id) {
    add("duplicate_id", "two nodes publish as '" + v.last.boat_id + "' (runs " +
                            std::to_string(v.last.boot_id) + " and " +
                            std::to_string(v.duplicate_boot_id) +
                            "): give each its own --boat-id; meanwhile the later one is "
                            "recorded under an id of its own (in the sessions list)");
  }
  if (std::abs(v.clock_offset_ms) > kClockSuspectMs) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "boat clock %+.1f s from the shore's (no time fix?)",
                  v.clock_offset_ms * 1e-3);
    add("clock_suspect", buf);
  }
  static constexpr std::pair<std::uint32_t, const char*> kSensorBits[] = {
      {msg::SENSOR_NO_DATA, "no IMU data"},
      {msg::SENSOR_NON_FINITE, "NaN/Inf samples rejected"},
      {msg::SENSOR_SATURATED, "IMU saturated"},
      {msg::SENSOR_TIME_BACKWARDS, "IMU time went backwards"},
      {msg::SENSOR_BAD_FRAMES, "garbage on a serial line"},
      {msg::SENSOR_HEADING_DEGRADED, "a heading sensor excluded"},
  };
  std::string sensors;
  for (const auto& [bit, text] : kSensorBits)
    if (health & bit) sensors += (sensors.empty() ? "" : ", ") + std::string(text);
  if (!sensors.empty()) add("sensor", sensors);
  return out;
}

/// `"text"` with JSON's escapes. Text with any byte above ASCII goes through nlohmann's
/// serialiser, which replaces what is not valid UTF-8 (to_json_text); ids, groups and the
/// shore's own words are ASCII, so the live frames take the short way.
void append_json_string(std::string& out, std::string_view text) {
  for (const char c : text) {
    if (static_cast<unsigned char>(c) >= 0x80) {
      out += to_json_text(json(std::string(text)));
      return;
    }
  }
  out += '"';
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  out += '"';
}

std::string boat_json(const BoatView& v) {
  const AttitudeSample& s = v.last;
  std::string out;
  out.reserve(1024);
  {
    JsonObjectText o(out);
    o.string("id", s.boat_id);
    o.string("kind", "boat");
    o.string("group", v.status ? v.status->group : std::string());
    o.integer("t_utc_ns", s.t_utc_ns);
    o.string("last_sample_time", iso8601(s.t_utc_ns));
    o.key("leds");
    {
      JsonObjectText leds(out);
      leds.integer("left", s.leds[0]);
      leds.integer("right", s.leds[1]);
      leds.integer("up", s.leds[2]);
      leds.integer("down", s.leds[3]);
      leds.integer("count", s.led_count);
    }
    o.string("alarm_state", v.alarm_state);
    o.boolean("stale", v.stale);
    o.integer("samples_received", v.samples_received);
    o.number("clock_offset_ms", v.clock_offset_ms);
    o.boolean("clock_suspect", std::abs(v.clock_offset_ms) > kClockSuspectMs);
    // The sample's fields, as in the exports (sample_fields.hpp).
    o.exported(kAttitudeFields, &s);
    // Position: null without a fresh fix with a position (never the last one as if it were new).
    const bool positioned = v.fix && v.fix_fresh && v.fix->fix != "none";
    o.exported(kFixFields, positioned ? &*v.fix : static_cast<const FixSample*>(nullptr));
    if (v.fix && v.fix_fresh) {
      o.string("gnss_fix", v.fix->fix);
    } else {
      o.null("gnss_fix");
    }
    if (v.fix) {
      // GNSS time minus the boat's clock at the fix: the boat clock's true error (plus the
      // receiver's output latency, tens of ms), beside clock_offset_ms (shore clock minus boat).
      o.key("gnss");
      JsonObjectText g(out);
      g.integer("satellites", v.fix->satellites);
      g.number("hdop", v.fix->hdop);
      g.string("fix_time", iso8601(v.fix->t_utc_ns));
      if (v.fix->gnss_utc_ns) {
        g.number("clock_offset_ms", (static_cast<double>(v.fix->gnss_utc_ns) -
                                     static_cast<double>(v.fix->t_utc_ns)) *
                                        1e-6);
      } else {
        g.null("clock_offset_ms");
      }
    }
    o.boolean("duplicate_id", v.duplicate_id);
    o.raw("problems", to_json_text(boat_problems(v)));
    if (v.status) {
      o.key("status");
      JsonObjectText st(out);
      st.string("software_version", v.status->software_version);
      st.number("uptime_s", v.status->uptime_s);
      st.integer("sensor_health", v.status->sensor_health);
      st.string("health_text", v.status->health_text);
    }
  }
  return out;
}

std::string boats_json(const std::vector<BoatView>& boats) {
  std::string out = "[";
  for (const auto& b : boats) {
    if (out.size() > 1) out += ',';
    out += boat_json(b);
  }
  out += ']';
  return out;
}

json rule_object(const AlarmRule& r) {
  return {{"id", r.id},
          {"scope", r.scope},
          {"quantity", to_string(r.quantity)},
          {"min_deg", r.min_deg},
          {"max_deg", r.max_deg},
          {"hold_s", r.hold_s},
          {"hysteresis_deg", r.hysteresis_deg},
          {"level", to_string(r.level)},
          {"enabled", r.enabled}};
}

namespace {
template <class T>
T field(const json& j, const char* name, const T& fallback, bool required) {
  if (!j.contains(name)) {
    if (required) throw HttpError(400, std::string("rule: missing field '") + name + "'");
    return fallback;
  }
  const json& v = j.at(name);
  if constexpr (std::is_same_v<T, double>) {
    if (!v.is_number()) throw HttpError(400, std::string("rule: '") + name + "' must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw HttpError(400, std::string("rule: '") + name + "' must be finite");
    return d;
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!v.is_boolean())
      throw HttpError(400, std::string("rule: '") + name + "' must be true/false");
    return v.get<bool>();
  } else {
    if (!v.is_string()) throw HttpError(400, std::string("rule: '") + name + "' must be a string");
    return v.get<std::string>();
  }
}
}  // namespace

AlarmRule rule_from_json(const json& j) {
  if (!j.is_object()) throw HttpError(400, "rule: expected an object");
  static const std::set<std::string> kKnown = {"id",      "scope",  "quantity",       "min_deg",
                                               "max_deg", "hold_s", "hysteresis_deg", "level",
                                               "enabled"};
  for (const auto& [key, value] : j.items())
    if (!kKnown.count(key)) throw HttpError(400, "rule: unknown field '" + key + "'");
  AlarmRule r;
  r.id = field<std::string>(j, "id", "", true);
  r.scope = field<std::string>(j, "scope", "fleet", false);
  const auto q = parse_quantity(field<std::string>(j, "quantity", "", true));
  if (!q) throw HttpError(400, "rule: quantity must be heel or pitch");
  r.quantity = *q;
  r.min_deg = field<double>(j, "min_deg", -90.0, false);
  r.max_deg = field<double>(j, "max_deg", 90.0, false);
  r.hold_s = field<double>(j, "hold_s", 0.0, false);
  r.hysteresis_deg = field<double>(j, "hysteresis_deg", 0.0, false);
  const auto level = parse_level(field<std::string>(j, "level", "warn", false));
  if (!level) throw HttpError(400, "rule: level must be warn or alarm");
  r.level = *level;
  r.enabled = field<bool>(j, "enabled", true, false);
  if (const std::string why = r.validate(); !why.empty()) throw HttpError(400, "rule: " + why);
  return r;
}

std::vector<AlarmRule> rules_from_body(const std::string& body) {
  json parsed;
  try {
    parsed = json::parse(body);
  } catch (const json::exception&) {
    // Not only parse_error: a number beyond double ("1e400") is an out_of_range, which used to
    // escape as a 500 (found by tests/fuzz/fuzz_rest).
    throw HttpError(400, "body is not valid JSON");
  }
  if (!parsed.is_array()) throw HttpError(400, "body must be a JSON array of rules");
  if (parsed.size() > kMaxRules)
    throw HttpError(400, "at most " + std::to_string(kMaxRules) + " rules");
  std::vector<AlarmRule> rules;
  std::set<std::string> ids;
  for (const auto& j : parsed) {
    rules.push_back(rule_from_json(j));
    if (!ids.insert(rules.back().id).second)
      throw HttpError(400, "duplicate rule id '" + rules.back().id + "'");
  }
  return rules;
}

json event_object(const AlarmEvent& e) {
  json j = {{"id", e.id},
            {"boat_id", e.boat_id},
            {"rule_id", e.rule_id},
            {"level", to_string(e.level)},
            {"phase", to_string(e.phase)},
            {"raised_at", iso8601(e.raised_ns)},
            {"raised_t_s", static_cast<double>(e.raised_ns) * 1e-9},
            {"value_deg", finite_or_null(e.value_deg)},
            {"message", e.message}};
  j["acknowledged_at"] = e.acknowledged_ns ? json(iso8601(e.acknowledged_ns)) : json(nullptr);
  j["silenced_at"] = e.silenced_ns ? json(iso8601(e.silenced_ns)) : json(nullptr);
  j["cleared_at"] = e.cleared_ns ? json(iso8601(e.cleared_ns)) : json(nullptr);
  return j;
}

json session_object(const SessionInfo& s) {
  return {{"id", s.id},
          {"boat_id", s.boat_id},
          {"start", iso8601(s.start_ns)},
          {"end", iso8601(s.end_ns)},
          {"start_t_s", static_cast<double>(s.start_ns) * 1e-9},
          {"end_t_s", static_cast<double>(s.end_ns) * 1e-9},
          {"duration_s", static_cast<double>(s.end_ns - s.start_ns) * 1e-9},
          {"samples", s.samples}};
}

json athlete_object(const AthleteView& v) {
  const WearableSample& w = v.last;
  return {{"id", w.athlete_id},
          {"kind", "wearable"},
          {"seq", w.seq},
          {"t_utc_ns", w.t_utc_ns},
          {"last_sample_time", iso8601(w.t_utc_ns)},
          {"steps", w.steps},
          {"cadence_spm", finite_or_null(w.cadence_spm)},
          {"gait", w.gait},
          {"pose", w.pose},
          {"x_m", finite_or_null(w.x_m)},
          {"y_m", finite_or_null(w.y_m)},
          {"heading_deg", finite_or_null(w.heading_deg)},
          {"distance_m", finite_or_null(w.distance_m)},
          {"stale", v.stale}};
}

}  // namespace telltale::shore
