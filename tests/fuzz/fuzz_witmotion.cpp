// libFuzzer target: the WitMotion 0x55 decoder (boat_node/sensors/witmotion.hpp). Arbitrary bytes
// are decoded once whole and once cut into pieces (serial reads end anywhere, also inside a
// packet); a sample built from the input is encoded and decoded back.
//
// Invariants beyond "no crash": the cut stream gives the same samples and counters as the whole
// one; every byte is accounted for (skipped, in a good packet, or at most 10 waiting for the rest
// of a packet); samples hold finite values inside the module's ranges (gyro NaN only when the
// cycle had no gyro packet); encode -> decode returns the sample to within one count.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"
#include "witmotion.hpp"

namespace {

using telltale::sensors::WitMotionDecoder;
using telltale::sensors::WitMotionParams;
using telltale::sensors::WitMotionStats;
using telltale::sensors::WitSample;

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;

struct Decoded {
  std::vector<WitSample> samples;
  WitMotionStats stats;
};

Decoded decode(std::span<const std::uint8_t> bytes, std::uint8_t seed) {
  Decoded out;
  WitMotionDecoder d([&](const WitSample& s) { out.samples.push_back(s); });
  // Pieces of up to 23 bytes: about two packets, so cuts fall inside and between them.
  telltale::fuzz::feed_in_pieces(bytes.size(), seed, 23, [&](std::size_t pos, std::size_t n) {
    d.feed(bytes.subspan(pos, n), 1.0);
  });
  d.flush();
  out.stats = d.stats();
  return out;
}

bool same_sample(const WitSample& a, const WitSample& b) {
  using telltale::fuzz::same;
  for (int i = 0; i < 3; ++i) {
    if (!same(a.imu.acc_body_m_s2[i], b.imu.acc_body_m_s2[i]) ||
        !same(a.imu.gyro_body_rad_s[i], b.imu.gyro_body_rad_s[i]) ||
        !same(a.mag_uT[i], b.mag_uT[i]) || !same(a.angle_deg[i], b.angle_deg[i]))
      return false;
  }
  return a.has_gyro == b.has_gyro && a.has_mag == b.has_mag && a.has_angle == b.has_angle &&
         a.has_pressure == b.has_pressure && same(a.pressure_pa, b.pressure_pa) &&
         same(a.height_m, b.height_m) && same(a.temperature_c, b.temperature_c) &&
         same(a.imu.t_s, b.imu.t_s);
}

void check_sample(const WitSample& s, const WitMotionParams& p) {
  const double acc_max = p.acc_range_g * kG;
  // The decoder's scale is range * (pi / 180) / 32768 and full scale 32768 counts: the bound must
  // be formed the same way ((range * pi) / 180 can be one ulp below it; a fuzzed range found it).
  const double gyro_max = p.gyro_range_deg_s * (M_PI / 180.0);
  FUZZ_CHECK(s.imu.acc_body_m_s2.allFinite());
  FUZZ_CHECK(s.imu.acc_body_m_s2.cwiseAbs().maxCoeff() <= acc_max);
  if (s.has_gyro) {
    FUZZ_CHECK(s.imu.gyro_body_rad_s.allFinite());
    FUZZ_CHECK(s.imu.gyro_body_rad_s.cwiseAbs().maxCoeff() <= gyro_max);
  } else {
    FUZZ_CHECK(s.imu.gyro_body_rad_s.array().isNaN().all());
  }
  FUZZ_CHECK(s.angle_deg.allFinite() && s.angle_deg.cwiseAbs().maxCoeff() <= p.angle_range_deg);
  FUZZ_CHECK(s.mag_uT.allFinite() && std::isfinite(s.pressure_pa) && std::isfinite(s.height_m) &&
             std::isfinite(s.temperature_c));
}

/// A sample on the module's count grid from the input, through the encoder and the decoder.
void check_round_trip(telltale::fuzz::Input& in) {
  const WitMotionParams p;
  const auto counts = [&in] { return static_cast<double>(static_cast<std::int16_t>(in.u16())); };
  WitSample s;
  const double ka = p.acc_range_g * kG / 32768.0;
  const double kw = p.gyro_range_deg_s * M_PI / 180.0 / 32768.0;
  const double kang = p.angle_range_deg / 32768.0;
  s.imu.acc_body_m_s2 = {ka * counts(), ka * counts(), ka * counts()};
  s.temperature_c = counts() / 100.0;
  const std::uint8_t parts = in.byte();
  s.has_gyro = (parts & 1) != 0;
  s.has_angle = (parts & 2) != 0;
  s.has_mag = (parts & 4) != 0;
  if (s.has_gyro) s.imu.gyro_body_rad_s = {kw * counts(), kw * counts(), kw * counts()};
  if (s.has_angle) s.angle_deg = {kang * counts(), kang * counts(), kang * counts()};
  if (s.has_mag) s.mag_uT = p.mag_uT_per_lsb * Eigen::Vector3d(counts(), counts(), counts());
  const std::vector<std::uint8_t> bytes = telltale::sensors::encode_wit_sample(s, p);
  const Decoded d = decode(bytes, 0);
  FUZZ_CHECK(d.samples.size() == 1);
  FUZZ_CHECK(d.stats.frames * 11 == bytes.size() && d.stats.bad_checksum == 0);
  const WitSample& b = d.samples[0];
  FUZZ_CHECK(b.has_gyro == s.has_gyro && b.has_angle == s.has_angle && b.has_mag == s.has_mag);
  FUZZ_CHECK((b.imu.acc_body_m_s2 - s.imu.acc_body_m_s2).cwiseAbs().maxCoeff() <= 1e-9 * ka);
  FUZZ_CHECK(std::fabs(b.temperature_c - s.temperature_c) <= 1e-9);
  if (s.has_gyro)
    FUZZ_CHECK((b.imu.gyro_body_rad_s - s.imu.gyro_body_rad_s).cwiseAbs().maxCoeff() <= 1e-9 * kw);
  if (s.has_angle) FUZZ_CHECK((b.angle_deg - s.angle_deg).cwiseAbs().maxCoeff() <= 1e-9 * kang);
  if (s.has_mag) FUZZ_CHECK((b.mag_uT - s.mag_uT).cwiseAbs().maxCoeff() <= 1e-9);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  telltale::fuzz::Input in(data, size);
  const std::uint8_t seed = in.byte();
  const std::string_view rest = in.rest();
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(rest.data()),
                                            rest.size());
  const Decoded whole = decode(bytes, 0);
  const Decoded cut = decode(bytes, static_cast<std::uint8_t>(seed | 1));
  FUZZ_CHECK(whole.samples.size() == cut.samples.size());
  for (std::size_t i = 0; i < whole.samples.size(); ++i)
    FUZZ_CHECK(same_sample(whole.samples[i], cut.samples[i]));
  const WitMotionStats& w = whole.stats;
  const WitMotionStats& c = cut.stats;
  FUZZ_CHECK(w.frames == c.frames && w.bad_checksum == c.bad_checksum &&
             w.skipped_bytes == c.skipped_bytes && w.unknown_type == c.unknown_type &&
             w.samples == c.samples);
  FUZZ_CHECK(w.samples == whole.samples.size() && w.unknown_type <= w.frames &&
             w.samples <= w.frames);
  const std::uint64_t accounted = w.skipped_bytes + 11 * w.frames;
  FUZZ_CHECK(accounted <= bytes.size() && bytes.size() - accounted <= 10);
  for (const WitSample& s : whole.samples) check_sample(s, WitMotionParams{});

  telltale::fuzz::Input again(data, size);
  check_round_trip(again);
  return 0;
}
