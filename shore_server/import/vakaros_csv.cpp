#include "vakaros_csv.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <string>

#include "telltale/fusion/angles.hpp"

namespace telltale::shore::import {
namespace {

constexpr std::size_t kMaxLine = 4096;
constexpr double kKnotToMS = 1852.0 / 3600.0;

std::string lower_trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '"' || s.back() == '\r')) s.remove_suffix(1);
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool blank(std::string_view s) {
  for (char c : s)
    if (c != ',' && c != ' ' && c != '\t' && c != '\r' && c != ';') return false;
  return true;
}

enum Column { kTime, kLat, kLon, kSog, kCog, kHdg, kHeel, kPitch, kColumns };

/// Reads one line into `line` (without the newline). False at the end of the input. `too_long`
/// is set when the line exceeded kMaxLine (the rest of it is consumed).
bool read_line(std::istream& in, std::string& line, bool& too_long, bool& had_newline) {
  line.clear();
  too_long = false;
  had_newline = false;
  char c;
  bool any = false;
  while (in.get(c)) {
    any = true;
    if (c == '\n') {
      had_newline = true;
      return true;
    }
    if (line.size() < kMaxLine) {
      line.push_back(c);
    } else {
      too_long = true;
    }
  }
  return any;
}

}  // namespace

ParseResult parse_vakaros_csv(std::istream& in, const ImportOptions& options, ImportSink& sink) {
  ParseResult r;
  auto fail = [&](std::uint64_t line_no, const std::string& what) {
    r.status = ParseStatus::kError;
    r.message = "line " + std::to_string(line_no) + ": " + what;
    return r;
  };
  std::string line;
  bool too_long = false, newline = false;
  std::uint64_t line_no = 0;
  // Header: the first line that is not blank.
  std::array<int, kColumns> col;
  col.fill(-1);
  for (;;) {
    if (!read_line(in, line, too_long, newline)) return fail(line_no, "no header row: empty file");
    ++line_no;
    if (too_long) return fail(line_no, "longer than 4096 bytes: not an Atlas CSV");
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!blank(line)) break;
  }
  {
    int i = 0;
    std::size_t start = 0;
    for (std::size_t k = 0; k <= line.size(); ++k) {
      if (k < line.size() && line[k] != ',') continue;
      const std::string name = lower_trimmed(std::string_view(line).substr(start, k - start));
      auto set = [&](Column c) {
        if (col[c] < 0) col[c] = i;
      };
      if (name == "timestamp" || name == "time") set(kTime);
      else if (name == "latitude" || name == "lat") set(kLat);
      else if (name == "longitude" || name == "lon") set(kLon);
      else if (name == "sog_kts") set(kSog);
      else if (name == "cog") set(kCog);
      else if (name == "hdg_true") set(kHdg);
      else if (name == "heel" || name == "roll") set(kHeel);
      else if (name == "trim" || name == "pitch") set(kPitch);
      ++i;
      start = k + 1;
    }
  }
  if (col[kTime] < 0 || col[kLat] < 0 || col[kLon] < 0)
    return fail(line_no, "header lacks timestamp, latitude and longitude: not an Atlas CSV");
  int needed = 0;
  for (int c : col) needed = std::max(needed, c + 1);

  std::array<std::string_view, 64> cells;
  while (read_line(in, line, too_long, newline)) {
    ++line_no;
    if (too_long) return fail(line_no, "longer than 4096 bytes");
    if (blank(line)) {
      ++r.skipped;
      continue;
    }
    std::size_t n = 0;
    std::size_t start = 0;
    const std::string_view sv(line);
    for (std::size_t k = 0; k <= sv.size() && n < cells.size(); ++k) {
      if (k < sv.size() && sv[k] != ',') continue;
      cells[n++] = sv.substr(start, k - start);
      start = k + 1;
    }
    if (static_cast<int>(n) < needed)
      return fail(line_no, std::string("row has ") + std::to_string(n) + " cells, the header " +
                               std::to_string(needed) + (newline ? "" : " (file cut short?)"));
    auto value = [&](Column c, double lo, double hi, const char* name,
                     double& out) -> std::optional<std::string> {
      if (col[c] < 0) return std::nullopt;
      const std::string_view cell = cells[static_cast<std::size_t>(col[c])];
      bool empty = true;
      for (char ch : cell)
        if (ch != ' ' && ch != '\r') empty = false;
      if (empty) return std::nullopt;
      const auto v = parse_decimal(cell);
      if (!v) return std::string(name) + " '" + std::string(cell) + "' is not a number";
      if (*v < lo || *v > hi)
        return std::string(name) + " " + std::string(cell) + " out of range";
      out = *v;
      return std::nullopt;
    };
    bool had_zone = false;
    auto t = parse_iso_time(cells[static_cast<std::size_t>(col[kTime])], options.utc_offset_s,
                            &had_zone);
    if (!t && options.local_offset_s) {
      // Local time in a named zone: read as if UTC, then moved by the zone's offset at that time.
      t = parse_iso_time(cells[static_cast<std::size_t>(col[kTime])], 0, &had_zone);
      if (t && !had_zone) {
        const std::int64_t local_s = static_cast<std::int64_t>(*t / 1'000'000'000ULL);
        const std::int64_t utc_ns =
            static_cast<std::int64_t>(*t) - options.local_offset_s(local_s) * 1'000'000'000LL;
        t = utc_ns > 0 ? std::optional<std::uint64_t>(static_cast<std::uint64_t>(utc_ns))
                       : std::nullopt;
      }
    }
    if (!t) {
      const auto probe = parse_iso_time(cells[static_cast<std::size_t>(col[kTime])], 0, &had_zone);
      if (probe && !had_zone && !options.utc_offset_s && !options.local_offset_s)
        return fail(line_no, "time '" + std::string(cells[static_cast<std::size_t>(col[kTime])]) +
                                 "' has no UTC offset: give the time zone of the recording (tz)");
      return fail(line_no, "timestamp '" + std::string(cells[static_cast<std::size_t>(col[kTime])]) +
                               "' is not an ISO 8601 time");
    }
    ImportPoint p;
    p.t_utc_ns = *t;
    double sog_kn = kNaN, heel = kNaN, pitch = kNaN;
    for (auto e : {value(kLat, -90, 90, "latitude", p.lat_deg),
                   value(kLon, -180, 180, "longitude", p.lon_deg),
                   value(kSog, 0, 200, "sog_kts", sog_kn), value(kCog, -360, 720, "cog", p.cog_deg),
                   value(kHdg, -360, 720, "hdg_true", p.heading_deg),
                   value(kHeel, -180, 180, "heel", heel), value(kPitch, -90, 90, "trim", pitch)})
      if (e) return fail(line_no, *e);
    if (std::isnan(p.lat_deg) != std::isnan(p.lon_deg))
      return fail(line_no, "a latitude without a longitude or the reverse");
    p.sog_m_s = sog_kn * kKnotToMS;
    p.cog_deg = fusion::wrap_360_deg(p.cog_deg);
    p.heading_deg = fusion::wrap_360_deg(p.heading_deg);
    p.heel_deg = heel;
    p.pitch_deg = pitch;
    apply_offsets(options, p);
    sink.point(p);
    ++r.points;
  }
  if (r.points == 0) return fail(line_no, "no data rows");
  return r;
}

}  // namespace telltale::shore::import
