#include "nmea_log.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <string>

#include "nmea.hpp"
#include "nmea_gnss.hpp"
#include "nmea_wind.hpp"
#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::shore::import {
namespace {

using sensors::NmeaFrame;
using sensors::NmeaStatus;

constexpr std::size_t kMaxLine = 1024;

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::toupper(static_cast<unsigned char>(a[i])) !=
        std::toupper(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

/// "ddmm.mmmm" / "dddmm.mmmm" with its hemisphere letter.
bool coordinate(std::string_view v, std::string_view dir, double max_deg, char plus, char minus,
                double& out) {
  double x;
  if (dir.size() != 1 || (dir[0] != plus && dir[0] != minus) || !sensors::parse_nmea_number(v, x))
    return false;
  const double deg = std::floor(x / 100.0);
  const double min = x - deg * 100.0;
  if (min >= 60.0 || deg > max_deg) return false;
  out = (deg + min / 60.0) * (dir[0] == minus ? -1.0 : 1.0);
  return std::fabs(out) <= max_deg;
}

bool time_of_day(std::string_view f, double& out) {
  double v;
  if (f.size() < 6 || !sensors::parse_nmea_number(f, v)) return false;
  const double hh = std::floor(v / 10000.0), mm = std::floor(std::fmod(v, 10000.0) / 100.0);
  const double ss = std::fmod(v, 100.0);
  if (hh > 23 || mm > 59 || ss >= 61) return false;
  out = hh * 3600.0 + mm * 60.0 + ss;
  return true;
}

/// The line's own time stamp (before the sentence), in ns; 0 when none.
std::uint64_t prefix_time(std::string_view prefix) {
  while (!prefix.empty() && (prefix.back() == ' ' || prefix.back() == ';' ||
                             prefix.back() == '\t' || prefix.back() == ','))
    prefix.remove_suffix(1);
  if (prefix.empty()) return 0;
  if (const auto t = parse_iso_time(prefix, std::nullopt)) return *t;
  bool all_digits = true;
  for (char c : prefix)
    if (!std::isdigit(static_cast<unsigned char>(c)) && c != '.') all_digits = false;
  if (!all_digits) return 0;
  const auto v = parse_decimal(prefix);
  if (!v || *v <= 0) return 0;
  if (*v > 1e11 && *v < 7.3e12) return static_cast<std::uint64_t>(*v * 1e6);  // ms
  if (*v > 1e8 && *v < 7.3e9) return static_cast<std::uint64_t>(*v * 1e9);    // s
  return 0;
}

/// Splits a log line into its time stamp and its sentence ("$..." or "!...").
bool split_line(std::string_view line, std::string_view& prefix, std::string_view& sentence) {
  // Signal K: "ms;N;sentence" (the middle field names the source).
  const std::size_t d = line.find_first_of("$!");
  if (d == std::string_view::npos) return false;
  prefix = line.substr(0, d);
  sentence = line.substr(d);
  while (!sentence.empty() && (sentence.back() == '\r' || sentence.back() == ' '))
    sentence.remove_suffix(1);
  if (!prefix.empty()) {
    const std::size_t semi = prefix.find(';');
    if (semi != std::string_view::npos) prefix = prefix.substr(0, semi);
  }
  return true;
}

class Epochs {
 public:
  Epochs(const ImportOptions& options, ImportSink& sink, ParseResult& r)
      : options_(options), sink_(sink), r_(r), days_(options.date_days.value_or(-1)) {}

  void line_time(std::uint64_t t_ns) {
    if (t_ns != 0) line_ns_ = t_ns;
  }
  /// A sentence with a time of day: a new epoch when it differs from the open one.
  void at(double tod_s) {
    if (open_ && std::fabs(tod_s - tod_) < 1e-4) return;
    flush();
    if (open_ && tod_s < tod_ - 43200.0 && days_ >= 0) ++days_;  // past midnight
    open_ = true;
    tod_ = tod_s;
  }
  void position(double lat, double lon) {
    p_.lat_deg = lat;
    p_.lon_deg = lon;
  }
  void speed(double sog, double cog) {
    if (std::isfinite(sog)) p_.sog_m_s = sog;
    if (std::isfinite(cog)) p_.cog_deg = cog;
  }
  void heading(double deg) { heading_ = deg; }
  /// A wind sentence's reading, made the true wind when its epoch closes (it may need the
  /// epoch's heading, course and speed, which can come after it). The better kind replaces the
  /// worse within one epoch (fusion::wind_rank).
  void wind(const fusion::WindReading& w) {
    if (!wind_ || fusion::wind_rank(w.ref) >= fusion::wind_rank(wind_->ref)) wind_ = w;
  }
  void heel(double deg) { heel_ = deg; }
  void pitch(double deg) { pitch_ = deg; }
  /// Call after at() for the sentence that states it (RMC, ZDA).
  void date_from_sentence(std::int64_t days) { days_ = days; }

  void flush() {
    if (!open_) return;
    const bool has_data = std::isfinite(p_.lat_deg) || std::isfinite(p_.sog_m_s);
    if (has_data) {
      std::int64_t days = days_;
      if (days < 0 && line_ns_ != 0) {
        // The date of the line's stamp, moved a day where the stamp and the time of day straddle
        // midnight.
        const double stamp_s = static_cast<double>(line_ns_) * 1e-9;
        days = static_cast<std::int64_t>(stamp_s / 86400.0);
        const double t = static_cast<double>(days) * 86400.0 + tod_;
        if (t - stamp_s > 43200.0) --days;
        if (stamp_s - t > 43200.0) ++days;
      }
      if (days < 0 || (days == 0 && tod_ < 1.0)) {  // no date yet (or the epoch itself)
        ++r_.skipped;
      } else {
        p_.t_utc_ns = static_cast<std::uint64_t>(days) * 86400ULL * 1'000'000'000ULL +
                      static_cast<std::uint64_t>(std::llround(tod_ * 1e9));
        p_.heading_deg = take(heading_);
        p_.heel_deg = take(heel_);
        p_.pitch_deg = take(pitch_);
        apply_offsets(options_, p_);
        sink_.point(p_);
        ++r_.points;
        emit_wind();
      }
    }
    p_ = ImportPoint{};
  }

 private:
  void emit_wind() {
    if (!wind_) return;
    const fusion::WindReading w = *wind_;
    wind_.reset();
    const fusion::TrueWind t =
        fusion::true_wind(w, p_.heading_deg, p_.sog_m_s, p_.cog_deg, options_.declination_deg);
    if (std::isfinite(t.from_deg))
      sink_.wind({p_.t_utc_ns, t.from_deg, t.speed_m_s, fusion::nmea_wind_source(w.ref)});
  }

  /// A value is attached once, to the epoch it came in (or the next, when it came between two).
  static double take(double& held) {
    const double v = held;
    held = kNaN;
    return v;
  }
  const ImportOptions& options_;
  ImportSink& sink_;
  ParseResult& r_;
  std::int64_t days_;
  std::uint64_t line_ns_ = 0;
  bool open_ = false;
  double tod_ = 0.0;
  ImportPoint p_;
  double heading_ = kNaN, heel_ = kNaN, pitch_ = kNaN;
  std::optional<fusion::WindReading> wind_;
};

/// XDR: quadruples of type, value, unit, name.
bool xdr(std::string_view fields, Epochs& epochs) {
  std::array<std::string_view, 32> f;
  const std::size_t n = sensors::split_nmea_fields(fields, f);
  if (n > f.size() || n < 4) return false;
  bool any = false;
  for (std::size_t i = 0; i + 3 < n + 1 && i + 3 < f.size(); i += 4) {
    if (i + 3 >= n) break;
    if (f[i] != "A" && f[i] != "a") continue;
    const auto v = parse_decimal(f[i + 1]);
    if (!v || std::fabs(*v) > 180.0) continue;
    const std::string_view name = f[i + 3];
    if (iequals(name, "ROLL") || iequals(name, "HEEL")) {
      epochs.heel(*v);
      any = true;
    } else if (iequals(name, "PTCH") || iequals(name, "PITCH") || iequals(name, "TRIM")) {
      if (std::fabs(*v) <= 90.0) {
        epochs.pitch(*v);
        any = true;
      }
    }
  }
  return any;
}

}  // namespace

bool looks_like_nmea_line(std::string_view line) {
  std::string_view prefix, sentence;
  if (!split_line(line, prefix, sentence)) return false;
  if (!prefix.empty() && prefix_time(prefix) == 0) return false;
  sensors::NmeaParseOptions o;
  o.accept_missing_checksum = true;
  NmeaFrame frame;
  return sensors::frame_nmea(sentence, o, frame) == NmeaStatus::kOk;
}

ParseResult parse_nmea_log(std::istream& in, const ImportOptions& options, ImportSink& sink) {
  ParseResult r;
  Epochs epochs(options, sink, r);
  sensors::NmeaParseOptions o;
  o.accept_missing_checksum = true;
  std::string line;
  std::uint64_t lines = 0;
  char c;
  bool too_long = false;
  auto handle = [&](std::string_view text) {
    ++lines;
    std::string_view prefix, sentence;
    if (too_long || !split_line(text, prefix, sentence)) {
      if (!text.empty() && text != "\r") ++r.skipped;
      return;
    }
    epochs.line_time(prefix_time(prefix));
    NmeaFrame frame;
    if (sensors::frame_nmea(sentence, o, frame) != NmeaStatus::kOk) {
      ++r.skipped;
      return;
    }
    const std::string_view type = frame.type;
    bool used = false;
    if (type == "RMC" || type == "GGA" || type == "VTG" || type == "GNS") {
      const auto g = sensors::parse_nmea_gnss(sentence, o);
      if (g.status == NmeaStatus::kOk) {
        used = true;
        const auto& s = g.gnss;
        if (std::isfinite(s.time_of_day_s)) epochs.at(s.time_of_day_s);
        if (s.date_ddmmyy >= 0) {
          const int dd = s.date_ddmmyy / 10000, mm = s.date_ddmmyy / 100 % 100,
                    yy = s.date_ddmmyy % 100;
          if (const auto days = days_from_civil(yy < 80 ? 2000 + yy : 1900 + yy, mm, dd))
            epochs.date_from_sentence(*days);
        }
        if (!s.no_fix && std::isfinite(s.lat_deg) && std::isfinite(s.lon_deg))
          epochs.position(s.lat_deg, s.lon_deg);
        if (!s.no_fix) epochs.speed(s.sog_m_s, s.cog_deg);
      }
    } else if (type == "GLL") {
      std::array<std::string_view, 8> f;
      const std::size_t n = sensors::split_nmea_fields(frame.fields, f);
      double lat, lon, tod;
      if (n >= 6 && n <= f.size() && time_of_day(f[4], tod)) {
        used = true;
        epochs.at(tod);
        if (f[5] == "A" && coordinate(f[0], f[1], 90.0, 'N', 'S', lat) &&
            coordinate(f[2], f[3], 180.0, 'E', 'W', lon))
          epochs.position(lat, lon);
      }
    } else if (type == "ZDA") {
      std::array<std::string_view, 7> f;
      const std::size_t n = sensors::split_nmea_fields(frame.fields, f);
      double tod, d, m, y;
      // A day, month or year outside an int (a garbled 1e300) is no date, and converting it
      // would be undefined: whole numbers of a sane size only (the date check does the rest).
      const auto whole = [](double v) { return std::abs(v) < 1e6 && v == std::floor(v); };
      if (n >= 4 && n <= f.size() && time_of_day(f[0], tod) &&
          sensors::parse_nmea_number(f[1], d) && sensors::parse_nmea_number(f[2], m) &&
          sensors::parse_nmea_number(f[3], y) && whole(d) && whole(m) && whole(y)) {
        if (const auto days = days_from_civil(static_cast<int>(y), static_cast<int>(m),
                                              static_cast<int>(d))) {
          used = true;
          epochs.at(tod);
          epochs.date_from_sentence(*days);
        }
      }
    } else if (type == "HDT" || type == "HDG" || type == "HDM") {
      const auto h = sensors::parse_nmea_heading(sentence, o);
      if (h.status == NmeaStatus::kOk) {
        used = true;
        if (std::isfinite(h.heading.true_deg)) {
          epochs.heading(h.heading.true_deg);
        } else if (std::isfinite(h.heading.magnetic_deg) && std::isfinite(options.declination_deg)) {
          epochs.heading(fusion::wrap_360_deg(h.heading.magnetic_deg + options.declination_deg));
        }
      }
    } else if (type == "XDR") {
      used = xdr(frame.fields, epochs);
    } else if (type == "MWV" || type == "MWD") {
      const auto w = sensors::parse_nmea_wind(sentence, o);
      // A magnetic direction without the declination says nothing true: skipped, and it does
      // not displace a usable reading of its epoch.
      used = w.status == NmeaStatus::kOk &&
             (w.reading.ref != fusion::WindRef::kMagneticDirection ||
              std::isfinite(options.declination_deg));
      if (used) epochs.wind(w.reading);
    }
    if (!used) ++r.skipped;
  };
  while (in.get(c)) {
    if (c == '\n') {
      handle(line);
      line.clear();
      too_long = false;
    } else if (line.size() < kMaxLine) {
      line.push_back(c);
    } else {
      too_long = true;
    }
  }
  if (!line.empty()) handle(line);
  epochs.flush();
  if (r.points == 0) {
    r.status = ParseStatus::kError;
    r.message = "no position with a date in " + std::to_string(lines) +
                " lines (an NMEA log needs RMC or ZDA dates, a time stamp per line, or the date given)";
  }
  return r;
}

}  // namespace telltale::shore::import
