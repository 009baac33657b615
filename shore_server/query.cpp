#include "query.hpp"

#include <charconv>
#include <cmath>
#include <ctime>
#include <regex>

namespace telltale::shore {

namespace {
// Days since 1970-01-01 of a civil date (proleptic Gregorian), Howard Hinnant's algorithm.
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned mp = m > 2 ? m - 3 : m + 9;  // March-based month
  const unsigned doy = (153 * mp + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

constexpr double kMaxEpochS = 9.2e9;  // below 2^63 ns
}  // namespace

std::optional<std::uint64_t> parse_time_ns(const std::string& text) {
  if (text.empty() || text.size() > 40) return std::nullopt;
  // Epoch seconds: digits with an optional fraction, nothing else.
  static const std::regex kEpoch(R"(\d{1,11}(\.\d{1,9})?)");
  if (std::regex_match(text, kEpoch)) {
    // Integer and fraction apart: a double would lose nanoseconds at today's epoch.
    const std::size_t dot = text.find('.');
    const std::uint64_t seconds = std::stoull(text.substr(0, dot));
    if (static_cast<double>(seconds) > kMaxEpochS) return std::nullopt;
    std::uint64_t ns = seconds * 1000000000ULL;
    if (dot != std::string::npos) {
      std::string frac = text.substr(dot + 1);
      frac.resize(9, '0');
      ns += std::stoull(frac);
    }
    return ns;
  }
  static const std::regex kIso(
      R"((\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2})(?::(\d{2})(?:\.(\d{1,9}))?)?(Z|[+-]\d{2}:\d{2})?)");
  std::smatch m;
  if (!std::regex_match(text, m, kIso)) return std::nullopt;
  const int year = std::stoi(m[1]);
  const auto month = static_cast<unsigned>(std::stoi(m[2]));
  const auto day = static_cast<unsigned>(std::stoi(m[3]));
  const int hour = std::stoi(m[4]);
  const int minute = std::stoi(m[5]);
  const int second = m[6].matched ? std::stoi(m[6]) : 0;
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60)
    return std::nullopt;
  // Reject days past the end of the month (e.g. 2026-02-30).
  const std::int64_t days = days_from_civil(year, month, day);
  const std::int64_t next_month_days =
      month == 12 ? days_from_civil(year + 1, 1, 1) : days_from_civil(year, month + 1, 1);
  if (days >= next_month_days) return std::nullopt;
  std::int64_t seconds = days * 86400 + hour * 3600 + minute * 60 + second;
  if (m[8].matched && m[8] != "Z") {
    const std::string off = m[8];
    const int sign = off[0] == '-' ? -1 : 1;
    const int oh = std::stoi(off.substr(1, 2));
    const int om = std::stoi(off.substr(4, 2));
    if (oh > 23 || om > 59) return std::nullopt;
    seconds -= sign * (oh * 3600 + om * 60);
  }
  if (seconds < 0 || static_cast<double>(seconds) > kMaxEpochS) return std::nullopt;
  std::uint64_t ns = static_cast<std::uint64_t>(seconds) * 1000000000ULL;
  if (m[7].matched) {
    std::string frac = m[7];
    frac.resize(9, '0');
    ns += std::stoull(frac);
  }
  return ns;
}

std::optional<std::int64_t> parse_int(const std::string& text, std::int64_t min, std::int64_t max) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < min || v > max)
    return std::nullopt;
  return v;
}

bool valid_id(const std::string& text) {
  if (text.empty() || text.size() > 32) return false;
  for (char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

TimeRange parse_range(const std::string* from, const std::string* to) {
  TimeRange r;
  if (from) {
    const auto t = parse_time_ns(*from);
    if (!t) throw HttpError(400, "from: expected ISO-8601 UTC or epoch seconds");
    r.from_ns = *t;
  }
  if (to) {
    const auto t = parse_time_ns(*to);
    if (!t) throw HttpError(400, "to: expected ISO-8601 UTC or epoch seconds");
    r.to_ns = *t;
  }
  if (r.from_ns > r.to_ns) throw HttpError(400, "from is after to");
  return r;
}

}  // namespace telltale::shore
