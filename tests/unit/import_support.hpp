#pragma once
// A sink that keeps what a parser yields, and small encoders for the binary formats, for the
// import tests.
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "record.hpp"

namespace telltale::shore::import::test {

struct Collect : ImportSink {
  std::vector<ImportPoint> points;
  std::vector<ImportEvent> events;
  std::vector<ImportWind> winds;
  std::string device_name;
  void point(const ImportPoint& p) override { points.push_back(p); }
  void wind(const ImportWind& w) override { winds.push_back(w); }
  void event(const ImportEvent& e) override { events.push_back(e); }
  void device(std::string_view d) override { device_name = std::string(d); }
};

inline ParseResult run(Format f, const std::string& bytes, Collect& sink,
                       const ImportOptions& options = {}) {
  std::istringstream in(bytes);
  return parse_log(f, in, options, sink);
}

/// Little-endian writers.
inline void put_u8(std::string& s, unsigned v) { s.push_back(static_cast<char>(v & 0xFF)); }
inline void put_u16(std::string& s, unsigned v) {
  put_u8(s, v);
  put_u8(s, v >> 8);
}
inline void put_u32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) put_u8(s, v >> (8 * i));
}
inline void put_u64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) put_u8(s, static_cast<unsigned>(v >> (8 * i)));
}
inline void put_f32(std::string& s, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  put_u32(s, u);
}

/// Protobuf writers.
inline void pb_varint(std::string& s, std::uint64_t v) {
  while (v >= 0x80) {
    put_u8(s, static_cast<unsigned>(v | 0x80));
    v >>= 7;
  }
  put_u8(s, static_cast<unsigned>(v));
}
inline void pb_uint(std::string& s, unsigned field, std::uint64_t v) {
  pb_varint(s, field << 3);
  pb_varint(s, v);
}
inline void pb_sint(std::string& s, unsigned field, std::int64_t v) {
  pb_uint(s, field, static_cast<std::uint64_t>((v << 1) ^ (v >> 63)));
}
inline void pb_bytes(std::string& s, unsigned field, const std::string& body) {
  pb_varint(s, (field << 3) | 2);
  pb_varint(s, body.size());
  s += body;
}

}  // namespace telltale::shore::import::test
