#include "detect.hpp"

#include <cctype>
#include <string>

#include "nmea_log.hpp"
#include "vkx.hpp"
#include "vtk.hpp"

namespace telltale::shore::import {
namespace {

bool is_text(std::string_view s) {
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x09 || (c > 0x0D && c < 0x20) || c == 0x7F) return false;
  }
  return true;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::optional<Format> detect_format(std::string_view head) {
  if (head.empty()) return std::nullopt;
  if (head.rfind("\xEF\xBB\xBF", 0) == 0) head.remove_prefix(3);
  if (is_text(head)) {
    const std::string low = lower(head);
    if (low.find("<gpx") != std::string::npos) return Format::kGpx;
    // Lines of the head (the last may be cut: left out unless the head is the whole file).
    std::size_t nmea = 0, other = 0;
    bool first = true;
    std::size_t start = 0;
    while (start < head.size()) {
      std::size_t end = head.find('\n', start);
      if (end == std::string_view::npos) {
        if (head.size() >= kDetectBytes) break;
        end = head.size();
      }
      std::string_view line = head.substr(start, end - start);
      start = end + 1;
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
      if (line.find_first_not_of(", \t;") == std::string_view::npos) continue;
      if (first) {
        first = false;
        const std::string l = lower(line);
        if (l.find("timestamp") != std::string::npos && l.find("latitude") != std::string::npos &&
            l.find("longitude") != std::string::npos)
          return Format::kVakarosCsv;
      }
      (looks_like_nmea_line(line) ? nmea : other) += 1;
    }
    if (nmea > 0 && nmea >= other) return Format::kNmea;
    return std::nullopt;
  }
  const auto* p = reinterpret_cast<const unsigned char*>(head.data());
  if (p[0] == 0xFF && head.size() >= 9 && p[1] <= 0x20 && vkx_payload_size(p[8]) >= 0)
    return Format::kVkx;
  if (looks_like_vtk(head)) return Format::kVtk;
  return std::nullopt;
}

}  // namespace telltale::shore::import
