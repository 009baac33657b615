// libFuzzer target: the boat's session log record codec (boat_node/session_log.hpp, 96-byte .tlog
// records with a CRC-32). The backfill thread decodes whatever is on disk after a power cut.
//
// Invariants beyond "no crash": any 96 bytes either fail to decode or decode to a record whose
// fields encode back to the same bytes (no field is silently dropped or normalised); a record built
// from the input survives encode -> decode bit for bit; any single corrupted byte of an encoded
// record is refused (CRC-32 catches every error burst of 32 bits or less).
#include <array>
#include <cstdint>
#include <cstring>

#include "fuzz_support.hpp"
#include "session_log.hpp"

namespace {

using telltale::boat::kLogRecordBytes;
using telltale::boat::LogRecord;

// Magic and CRC (8), seq and time (16), six doubles (48), two floats (8), LEDs, count, level (6);
// the rest of the 96 bytes is zero padding, covered by the CRC but not by any field.
constexpr std::size_t kHeaderBytes = 8;
constexpr std::size_t kFieldsEnd = kHeaderBytes + 16 + 48 + 8 + 6;

bool same_bits(const LogRecord& a, const LogRecord& b) {
  std::array<unsigned char, kLogRecordBytes> ea{};
  std::array<unsigned char, kLogRecordBytes> eb{};
  telltale::boat::encode_record(a, ea.data());
  telltale::boat::encode_record(b, eb.data());
  return ea == eb;
}

LogRecord record_from(telltale::fuzz::Input& in) {
  LogRecord r;
  r.seq = in.u64();
  r.t_utc_ns = in.u64();
  r.heel_deg = in.raw_double();
  r.pitch_deg = in.raw_double();
  r.heading_deg = in.raw_double();
  r.heel_rate_deg_s = in.raw_double();
  r.pitch_rate_deg_s = in.raw_double();
  r.yaw_rate_deg_s = in.raw_double();
  r.accel_weight = static_cast<float>(in.u16()) / 65535.0f;
  r.quality = static_cast<float>(in.byte()) / 255.0f;
  for (auto& l : r.leds) l = in.byte();
  r.led_count = in.byte();
  r.level = in.byte();
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // 1. The input as raw records, as the reader meets them on disk.
  for (std::size_t off = 0; off + kLogRecordBytes <= size; off += kLogRecordBytes) {
    const auto r = telltale::boat::decode_record(data + off);
    if (!r) continue;
    std::array<unsigned char, kLogRecordBytes> again{};
    telltale::boat::encode_record(*r, again.data());
    FUZZ_CHECK(std::memcmp(again.data() + kHeaderBytes, data + off + kHeaderBytes,
                           kFieldsEnd - kHeaderBytes) == 0);
  }
  // 2. A record from the input: encode -> decode is the identity; one bad byte is refused.
  telltale::fuzz::Input in(data, size);
  const LogRecord r = record_from(in);
  std::array<unsigned char, kLogRecordBytes> buf{};
  telltale::boat::encode_record(r, buf.data());
  const auto back = telltale::boat::decode_record(buf.data());
  FUZZ_CHECK(back.has_value() && same_bits(*back, r));
  const std::size_t at = in.byte() % kLogRecordBytes;
  const auto flip = static_cast<unsigned char>(in.byte() | 1);
  buf[at] ^= flip;
  FUZZ_CHECK(!telltale::boat::decode_record(buf.data()).has_value());
  return 0;
}
