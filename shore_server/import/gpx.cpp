#include "gpx.hpp"

#include <cmath>
#include <string>

#include "telltale/fusion/angles.hpp"

namespace telltale::shore::import {
namespace {

constexpr std::size_t kMaxToken = 4096;

std::string_view local_name(std::string_view name) {
  const std::size_t colon = name.find(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

/// The value of attribute `name` in a tag's text ("trkpt lat=\"1\" lon='2'"), or nullopt.
std::optional<std::string_view> attribute(std::string_view tag, std::string_view name) {
  std::size_t pos = 0;
  while ((pos = tag.find(name, pos)) != std::string_view::npos) {
    const bool starts = pos > 0 && (tag[pos - 1] == ' ' || tag[pos - 1] == '\t' ||
                                    tag[pos - 1] == '\n' || tag[pos - 1] == '\r');
    std::size_t k = pos + name.size();
    while (k < tag.size() && (tag[k] == ' ' || tag[k] == '\t')) ++k;
    if (starts && k < tag.size() && tag[k] == '=') {
      ++k;
      while (k < tag.size() && (tag[k] == ' ' || tag[k] == '\t')) ++k;
      if (k >= tag.size() || (tag[k] != '"' && tag[k] != '\'')) return std::nullopt;
      const char q = tag[k];
      const std::size_t end = tag.find(q, k + 1);
      if (end == std::string_view::npos) return std::nullopt;
      return tag.substr(k + 1, end - k - 1);
    }
    pos += name.size();
  }
  return std::nullopt;
}

enum class Field { kNone, kTime, kSpeed, kCourse, kHeel, kPitch };

Field field_of(std::string_view local) {
  if (local == "time") return Field::kTime;
  if (local == "speed" || local == "sog_m_s") return Field::kSpeed;
  if (local == "course" || local == "cog_deg") return Field::kCourse;
  if (local == "heel_deg") return Field::kHeel;
  if (local == "pitch_deg") return Field::kPitch;
  return Field::kNone;
}

}  // namespace

ParseResult parse_gpx(std::istream& in, const ImportOptions& options, ImportSink& sink) {
  ParseResult r;
  std::uint64_t line = 1;
  auto fail = [&](std::uint64_t at, const std::string& what) {
    r.status = ParseStatus::kError;
    r.message = "line " + std::to_string(at) + ": " + what;
    return r;
  };
  std::string token;
  bool seen_root = false, closed_root = false;
  bool in_point = false;
  std::uint64_t point_line = 0;
  ImportPoint p;
  bool have_time = false;
  Field field = Field::kNone;
  std::string text;
  const std::optional<std::int64_t> offset =
      options.utc_offset_s ? options.utc_offset_s : std::optional<std::int64_t>(0);

  auto finish_point = [&]() -> bool {
    in_point = false;
    if (!have_time) return false;
    p.sog_m_s = std::isfinite(p.sog_m_s) && p.sog_m_s >= 0.0 && p.sog_m_s < 100.0 ? p.sog_m_s : kNaN;
    p.cog_deg = fusion::wrap_360_deg(p.cog_deg);
    apply_offsets(options, p);
    sink.point(p);
    ++r.points;
    return true;
  };

  int ch;
  while ((ch = in.get()) != std::char_traits<char>::eof()) {
    if (ch == '\n') ++line;
    if (ch != '<') {
      if (field != Field::kNone) {
        if (text.size() >= kMaxToken) return fail(line, "text longer than 4 KB");
        text.push_back(static_cast<char>(ch));
      }
      continue;
    }
    // A tag: read to its '>' (comments to "-->", CDATA to "]]>").
    token.clear();
    const std::uint64_t tag_line = line;
    bool closed = false;
    while ((ch = in.get()) != std::char_traits<char>::eof()) {
      if (ch == '\n') ++line;
      if (token.size() >= kMaxToken) return fail(tag_line, "tag longer than 4 KB");
      if (ch == '>') {
        const bool comment = token.rfind("!--", 0) == 0;
        const bool cdata = token.rfind("![CDATA[", 0) == 0;
        if ((!comment || (token.size() >= 5 && token.ends_with("--"))) &&
            (!cdata || token.ends_with("]]"))) {
          closed = true;
          break;
        }
      }
      token.push_back(static_cast<char>(ch));
    }
    if (!closed) return fail(tag_line, "the file ends inside a tag");
    if (token.empty() || token[0] == '?' || token[0] == '!') {
      if (token.rfind("![CDATA[", 0) == 0 && field != Field::kNone)
        text.append(token, 8, token.size() - 10);
      continue;
    }
    const bool end_tag = token[0] == '/';
    const bool self_closing = !end_tag && token.size() > 1 && token.back() == '/';
    std::string_view body(token);
    if (end_tag) body.remove_prefix(1);
    if (self_closing) body.remove_suffix(1);
    const std::size_t name_end = body.find_first_of(" \t\r\n");
    const std::string_view name = body.substr(0, name_end);
    const std::string_view local = local_name(name);

    if (!end_tag) {
      if (local == "gpx") {
        seen_root = true;
        if (const auto creator = attribute(body, "creator"); creator && !creator->empty())
          sink.device(*creator);
      } else if (local == "trkpt") {
        if (!seen_root) return fail(tag_line, "a track point outside <gpx>: not a GPX file");
        const auto lat_s = attribute(body, "lat"), lon_s = attribute(body, "lon");
        const double lat = lat_s ? parse_decimal(*lat_s).value_or(kNaN) : kNaN;
        const double lon = lon_s ? parse_decimal(*lon_s).value_or(kNaN) : kNaN;
        if (!(std::fabs(lat) <= 90.0) || !(std::fabs(lon) <= 180.0))
          return fail(tag_line, "track point without a valid lat and lon");
        p = ImportPoint{};
        p.lat_deg = lat;
        p.lon_deg = lon;
        have_time = false;
        in_point = true;
        point_line = tag_line;
        if (self_closing && !finish_point())
          return fail(tag_line, "track point without a time");
      } else if (in_point && !self_closing) {
        field = field_of(local);
        text.clear();
      }
      continue;
    }
    // End tags.
    if (local == "trkpt") {
      if (!in_point) return fail(tag_line, "</trkpt> without its <trkpt>");
      if (!finish_point()) return fail(point_line, "track point without a time");
    } else if (local == "gpx") {
      closed_root = true;
    } else if (in_point && field != Field::kNone && field == field_of(local)) {
      if (field == Field::kTime) {
        const auto t = parse_iso_time(text, offset);
        if (!t) return fail(tag_line, "time '" + text + "' is not an ISO 8601 time");
        p.t_utc_ns = *t;
        have_time = true;
      } else {
        const auto v = parse_decimal(text);
        if (!v) return fail(tag_line, std::string(local) + " '" + text + "' is not a number");
        if (field == Field::kSpeed) p.sog_m_s = *v;
        if (field == Field::kCourse) p.cog_deg = *v;
        if (field == Field::kHeel && std::fabs(*v) <= 180.0) p.heel_deg = *v;
        if (field == Field::kPitch && std::fabs(*v) <= 90.0) p.pitch_deg = *v;
      }
      field = Field::kNone;
    }
  }
  if (!seen_root) return fail(line, "no <gpx> element: not a GPX file");
  if (in_point) return fail(point_line, "the file ends inside a track point (cut short?)");
  if (!closed_root) return fail(line, "the file ends before </gpx> (cut short?)");
  if (r.points == 0) return fail(line, "no track points");
  return r;
}

}  // namespace telltale::shore::import
