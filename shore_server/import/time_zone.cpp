#include "time_zone.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace telltale::shore::import {
namespace {

std::int64_t be(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  if (n == 4) return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
  return static_cast<std::int64_t>(v);
}

}  // namespace

std::optional<TimeZone> TimeZone::load(const std::string& name) {
  if (name.empty() || name.size() > 64 || name.find("..") != std::string::npos || name[0] == '/')
    return std::nullopt;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '+' && c != '/')
      return std::nullopt;
  const char* dir = std::getenv("TZDIR");
  const std::string path = std::string(dir && *dir ? dir : "/usr/share/zoneinfo") + "/" + name;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;  // "Europe" is a folder
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::vector<unsigned char> d((std::istreambuf_iterator<char>(in)),
                                     std::istreambuf_iterator<char>());
  if (d.size() > (1u << 20)) return std::nullopt;
  // Header: "TZif", version, 15 reserved, then six counts.
  struct Counts {
    std::int64_t isut, isstd, leap, time, type, chars;
  };
  auto counts_at = [&](std::size_t off, Counts& c) {
    if (off + 44 > d.size() || d[off] != 'T' || d[off + 1] != 'Z' || d[off + 2] != 'i' ||
        d[off + 3] != 'f')
      return false;
    const unsigned char* p = d.data() + off + 20;
    c = {be(p, 4), be(p + 4, 4), be(p + 8, 4), be(p + 12, 4), be(p + 16, 4), be(p + 20, 4)};
    return c.isut >= 0 && c.isstd >= 0 && c.leap >= 0 && c.time >= 0 && c.type > 0 &&
           c.chars >= 0 && c.type < 256;
  };
  Counts c;
  if (!counts_at(0, c) || d[4] < '2') return std::nullopt;
  // Skip the version 1 block (32-bit times) to the version 2 header.
  const std::size_t v1 = static_cast<std::size_t>(c.time * 5 + c.type * 6 + c.chars + c.leap * 8 +
                                                  c.isstd + c.isut);
  const std::size_t h2 = 44 + v1;
  if (!counts_at(h2, c)) return std::nullopt;
  const std::size_t times = h2 + 44;
  const std::size_t idx = times + static_cast<std::size_t>(c.time) * 8;
  const std::size_t types = idx + static_cast<std::size_t>(c.time);
  if (types + static_cast<std::size_t>(c.type) * 6 > d.size()) return std::nullopt;
  std::vector<std::int32_t> type_offsets;
  for (std::int64_t i = 0; i < c.type; ++i)
    type_offsets.push_back(static_cast<std::int32_t>(be(d.data() + types + i * 6, 4)));
  TimeZone z;
  z.initial_ = type_offsets[0];
  for (std::int64_t i = 0; i < c.time; ++i) {
    const unsigned t = d[idx + static_cast<std::size_t>(i)];
    if (t >= type_offsets.size()) return std::nullopt;
    z.transitions_.push_back(be(d.data() + times + i * 8, 8));
    z.offsets_.push_back(type_offsets[t]);
  }
  if (!std::is_sorted(z.transitions_.begin(), z.transitions_.end())) return std::nullopt;
  return z;
}

std::int64_t TimeZone::offset_at_utc(std::int64_t utc_s) const {
  const auto it = std::upper_bound(transitions_.begin(), transitions_.end(), utc_s);
  if (it == transitions_.begin()) return initial_;
  return offsets_[static_cast<std::size_t>(it - transitions_.begin() - 1)];
}

std::int64_t TimeZone::offset_at_local(std::int64_t local_s) const {
  // The offset in force a day before (zones change at most once a day): if the local time reads
  // with it, that is the answer (in an autumn overlap: the first occurrence, before the change).
  const std::int64_t before = offset_at_utc(local_s - 86400);
  if (offset_at_utc(local_s - before) == before) return before;
  // Otherwise the time is after a change: the new offset, unless the time does not exist (the
  // spring gap), which keeps the offset before the change.
  const std::int64_t after = offset_at_utc(local_s - before);
  return offset_at_utc(local_s - after) == after ? after : before;
}

}  // namespace telltale::shore::import
