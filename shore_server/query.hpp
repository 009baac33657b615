#pragma once
/// \file
/// Strict parsing of REST inputs. Every bad value becomes an HttpError with the 4xx status that
/// says what was wrong; the server's one exception handler turns it into `{"error": "..."}`.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace telltale::shore {

class HttpError : public std::runtime_error {
 public:
  HttpError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  [[nodiscard]] int status() const { return status_; }

 private:
  int status_;
};

/// A time as ISO-8601 UTC (`2026-11-22T10:00:00Z`, fraction and `+hh:mm` offset allowed) or
/// epoch seconds (`1795300000.25`); nanoseconds since 1970. Nothing for malformed or out of
/// range (before 1970 or after 2262).
[[nodiscard]] std::optional<std::uint64_t> parse_time_ns(const std::string& text);
/// Whole number in [min, max]; nothing otherwise (text after the digits, overflow, NaN).
[[nodiscard]] std::optional<std::int64_t> parse_int(const std::string& text, std::int64_t min,
                                                    std::int64_t max);
/// Ids of boats, athletes and rules: 1-32 of [A-Za-z0-9_-].
[[nodiscard]] bool valid_id(const std::string& text);

/// A [from, to] range from optional query values; defaults to everything. Throws HttpError 400
/// for malformed times or from > to.
struct TimeRange {
  std::uint64_t from_ns = 0;
  std::uint64_t to_ns = UINT64_MAX;
};
[[nodiscard]] TimeRange parse_range(const std::string* from, const std::string* to);

}  // namespace telltale::shore
