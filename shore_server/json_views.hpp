#pragma once
/// \file
/// The JSON shapes of the REST API and the live stream (described in openapi.json), in one place.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "fleet.hpp"
#include "sample_fields.hpp"
#include "store.hpp"
#include "telltale/fusion/alarm_engine.hpp"

namespace telltale::shore {

/// JSON text of `j` that never throws on a string that is not valid UTF-8 (such bytes become
/// U+FFFD): a stored value from before the shore checked its input cannot fail a response.
/// Every response and stream frame is serialised through it, never through json::dump().
[[nodiscard]] std::string to_json_text(const nlohmann::json& j);

/// ISO-8601 UTC with milliseconds for ns since 1970.
[[nodiscard]] std::string iso8601(std::uint64_t t_utc_ns);
/// A number, or null when it is not finite.
[[nodiscard]] nlohmann::json finite_or_null(double v);
/// Appends `v` as JSON text: its shortest form that reads back to the same double, or null when
/// it is not finite. For columns of thousands of numbers (charts), written straight to text
/// instead of through a json array: a chart answer costs a tenth of what the array would.
void append_json_number(std::string& out, double v);
/// Appends `,"name":[...]`: `value(row)` of every row, each by append_json_number.
template <class Row, class Value>
void append_number_column(std::string& out, std::string_view name, const std::vector<Row>& rows,
                          Value value) {
  out += ",\"";
  out += name;
  out += "\":[";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (i) out += ',';
    append_json_number(out, static_cast<double>(value(rows[i])));
  }
  out += ']';
}

/// Appends `"text"` with JSON's escapes; text that is not valid UTF-8 has such bytes replaced by
/// U+FFFD (as to_json_text does).
void append_json_string(std::string& out, std::string_view text);

/// A JSON object written straight to text, member by member: the shapes written tens of
/// thousands of times a second (a boat's live frame, an exported sample row) cost a third of
/// what building a json object and dumping it did. `{` at construction, `}` at destruction.
class JsonObjectText {
 public:
  explicit JsonObjectText(std::string& out) : out_(out) { out_ += '{'; }
  ~JsonObjectText() { out_ += '}'; }
  JsonObjectText(const JsonObjectText&) = delete;
  JsonObjectText& operator=(const JsonObjectText&) = delete;

  /// `"name":`, after a comma when it is not the first member; the value follows.
  std::string& key(std::string_view name) {
    if (!first_) out_ += ',';
    first_ = false;
    out_ += '"';
    out_ += name;
    out_ += "\":";
    return out_;
  }
  void string(std::string_view name, std::string_view v) { append_json_string(key(name), v); }
  /// A number; null when it is not finite.
  void number(std::string_view name, double v) { append_json_number(key(name), v); }
  template <class Int>
  requires std::is_integral_v<Int>
  void integer(std::string_view name, Int v) {
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    key(name).append(buf, r.ptr);
  }
  void boolean(std::string_view name, bool v) { key(name) += v ? "true" : "false"; }
  void null(std::string_view name) { key(name) += "null"; }
  /// A value that is JSON text already.
  void raw(std::string_view name, std::string_view json_text) { key(name) += json_text; }

  /// Every exported field of `table` (sample_fields.hpp) from `record`: numbers that are not
  /// finite, and every field when there is no record, as null.
  template <class Table, class Record>
  void exported(const Table& table, const Record* record) {
    for_each_field<kExported>(table, [&](const auto& f) {
      if (!record) return null(f.name);
      const auto& v = f.get(*record);
      using V = std::remove_cvref_t<decltype(v)>;
      if constexpr (std::is_floating_point_v<V>) {
        number(f.name, static_cast<double>(v));
      } else if constexpr (std::is_integral_v<V>) {
        integer(f.name, v);
      } else {
        string(f.name, v);
      }
    });
  }

 private:
  std::string& out_;
  bool first_ = true;
};

/// What a coach should know is wrong with a boat, most serious first: `[{code, text}]` with
/// code "log_failing" (its session log cannot write), "duplicate_id" (two nodes under one id),
/// "clock_suspect" (its clock is off the shore's), "sensor" (the IMU's health flags). Empty when
/// all is well. The dashboard shows each as a badge on the boat's card.
[[nodiscard]] nlohmann::json boat_problems(const BoatView& view);
/// A boat as GET /boats/{id} and the live stream's `sample` frames carry it (openapi.json, Boat),
/// written straight to text.
[[nodiscard]] std::string boat_json(const BoatView& view);
/// `[boat, ...]`: GET /boats.
[[nodiscard]] std::string boats_json(const std::vector<BoatView>& boats);
[[nodiscard]] nlohmann::json rule_object(const AlarmRule& rule);
/// A rule from its JSON; throws HttpError 400 naming the field that is wrong.
[[nodiscard]] AlarmRule rule_from_json(const nlohmann::json& j);
/// Most rules one PUT /api/v1/alarms/rules may set.
inline constexpr std::size_t kMaxRules = 200;
/// The rules of a PUT /api/v1/alarms/rules body: a JSON array of at most kMaxRules rules with
/// distinct ids. Throws HttpError 400 (broken JSON, not an array, too many, a bad rule, a
/// duplicate id) and nothing else, whatever the bytes.
[[nodiscard]] std::vector<AlarmRule> rules_from_body(const std::string& body);
[[nodiscard]] nlohmann::json event_object(const AlarmEvent& event);
[[nodiscard]] nlohmann::json session_object(const SessionInfo& session);
[[nodiscard]] nlohmann::json athlete_object(const AthleteView& view);

}  // namespace telltale::shore
