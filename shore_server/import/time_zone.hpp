#pragma once
/// \file
/// IANA time zones ("Europe/Madrid") from the system's compiled zone files (TZif, RFC 8536,
/// /usr/share/zoneinfo or $TZDIR), for logs written in local time without an offset. Read once,
/// then pure lookups: thread-safe, unlike setting TZ for localtime/mktime. The version 2+ data
/// (64-bit transition times) is used; Debian's files list transitions up to 2037, after which the
/// last offset holds (the POSIX rule at the end of the file is not read).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace telltale::shore::import {

class TimeZone {
 public:
  /// The zone `name` (letters, digits, '_', '-', '+', '/'; no "..") or nullopt when there is no
  /// such zone or its file is not a TZif file.
  [[nodiscard]] static std::optional<TimeZone> load(const std::string& name);
  /// Seconds east of UTC in force at UTC time `utc_s`.
  [[nodiscard]] std::int64_t offset_at_utc(std::int64_t utc_s) const;
  /// Seconds east of UTC of the local time `local_s` (seconds since 1970 read as if local were
  /// UTC). A local time that does not exist (the spring gap) or exists twice (the autumn
  /// overlap) takes the offset before the change.
  [[nodiscard]] std::int64_t offset_at_local(std::int64_t local_s) const;

 private:
  std::vector<std::int64_t> transitions_;  ///< UTC seconds, ascending
  std::vector<std::int32_t> offsets_;      ///< offset from transitions_[i] on
  std::int32_t initial_ = 0;               ///< before the first transition
};

}  // namespace telltale::shore::import
