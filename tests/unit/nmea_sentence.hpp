#pragma once
// An NMEA 0183 sentence as a receiver sends it: "$" body "*" checksum CR LF. For tests that feed
// the boat's NMEA readers.

#include <cstdio>
#include <string>

namespace telltale::test {

inline std::string nmea(const std::string& body) {
  unsigned char cs = 0;
  for (char c : body) cs ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", cs);
  return "$" + body + tail;
}

}  // namespace telltale::test
