// libFuzzer target: NMEA 0183 heading and GNSS input (boat_node/sensors/nmea.hpp, nmea_gnss.hpp).
// The bytes go through the line assembler once whole and once cut into pieces (serial reads end
// anywhere), then every line through both parsers and the GNSS epochs into the gate; the bytes
// are also parsed as one line directly.
//
// Invariants beyond "no crash": the cut stream gives the same lines and counters as the whole one;
// a line starts with '$', holds no CR, LF or second '$' and is at most kNmeaMaxLine long; a parsed
// heading is in [0, 360) or NaN exactly where the header says it may be; a heading printed back
// into a sentence with its checksum parses to the same heading.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "gnss_gate.hpp"
#include "nmea.hpp"
#include "nmea_gnss.hpp"
#include "nmea_wind.hpp"

namespace {

using telltale::sensors::kNmeaMaxLine;
using telltale::sensors::NmeaHeading;
using telltale::sensors::NmeaLineAssembler;
using telltale::sensors::NmeaParseOptions;
using telltale::sensors::NmeaSentence;
using telltale::sensors::NmeaStatus;

bool in_range_or_nan(double v) { return std::isnan(v) || (v >= 0.0 && v < 360.0); }

double angle_diff_deg(double a, double b) {
  const double d = std::fmod(std::fabs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

void check_heading(const NmeaHeading& h) {
  FUZZ_CHECK(in_range_or_nan(h.true_deg) && in_range_or_nan(h.magnetic_deg));
  FUZZ_CHECK(h.talker[2] == '\0');
  switch (h.sentence) {
    case NmeaSentence::kHdt:
      FUZZ_CHECK(!std::isnan(h.true_deg) && std::isnan(h.magnetic_deg));
      break;
    case NmeaSentence::kHdm:
      FUZZ_CHECK(std::isnan(h.true_deg) && !std::isnan(h.magnetic_deg));
      break;
    case NmeaSentence::kHdg:
      FUZZ_CHECK(!std::isnan(h.magnetic_deg));
      // No variation, no true heading: the node must never get a guessed one.
      FUZZ_CHECK(std::isnan(h.variation_deg) == std::isnan(h.true_deg));
      FUZZ_CHECK(std::isnan(h.deviation_deg) || std::fabs(h.deviation_deg) <= 180.0);
      FUZZ_CHECK(std::isnan(h.variation_deg) || std::fabs(h.variation_deg) <= 180.0);
      break;
  }
}

/// The heading printed as the sentence a talker would send, with its checksum, parses back.
void check_round_trip(const NmeaHeading& h) {
  const bool is_true = !std::isnan(h.true_deg);
  const double v = is_true ? h.true_deg : h.magnetic_deg;
  char body[64];
  std::snprintf(body, sizeof body, "%c%c%s,%.4f,%c", h.talker[0], h.talker[1],
                is_true ? "HDT" : "HDM", v, is_true ? 'T' : 'M');
  unsigned sum = 0;
  for (const char* c = body; *c; ++c) sum ^= static_cast<unsigned char>(*c);
  char line[80];
  std::snprintf(line, sizeof line, "$%s*%02X\r\n", body, sum);
  const auto back = telltale::sensors::parse_nmea_heading(line);
  FUZZ_CHECK(back.status == NmeaStatus::kOk);
  FUZZ_CHECK(back.heading.had_checksum);
  const double got = is_true ? back.heading.true_deg : back.heading.magnetic_deg;
  FUZZ_CHECK(angle_diff_deg(got, v) <= 1e-4);
}

void parse_and_check(std::string_view line, const NmeaParseOptions& options) {
  const auto r = telltale::sensors::parse_nmea_heading(line, options);
  if (r.status != NmeaStatus::kOk) return;
  check_heading(r.heading);
  FUZZ_CHECK(r.heading.had_checksum || options.accept_missing_checksum);
  check_round_trip(r.heading);
}

void check_gnss(const telltale::sensors::NmeaGnss& g) {
  FUZZ_CHECK(std::isnan(g.lat_deg) == std::isnan(g.lon_deg));
  FUZZ_CHECK(std::isnan(g.lat_deg) || std::fabs(g.lat_deg) <= 90.0);
  FUZZ_CHECK(std::isnan(g.lon_deg) || std::fabs(g.lon_deg) <= 180.0);
  FUZZ_CHECK(std::isnan(g.sog_m_s) || (std::isfinite(g.sog_m_s) && g.sog_m_s >= 0.0));
  FUZZ_CHECK(in_range_or_nan(g.cog_deg));
  FUZZ_CHECK(std::isnan(g.time_of_day_s) || (g.time_of_day_s >= 0.0 && g.time_of_day_s < 86401.0));
  FUZZ_CHECK(g.talker[2] == '\0');
}

/// Every line through the GNSS parser, the epochs into the gate: what comes out is on contract.
void gnss_pipeline(const std::vector<std::string>& lines, const NmeaParseOptions& options) {
  telltale::sensors::GnssEpochAssembler epochs;
  telltale::boat::GnssGate gate;
  double t = 0.0;
  const auto gate_check = [&](const telltale::sensors::GnssReading& r) {
    if (r.fix != telltale::sensors::GnssFixKind::kNone)
      FUZZ_CHECK(std::isfinite(r.lat_deg) && std::isfinite(r.lon_deg));
    const auto f = gate.on_epoch(r, t, 1796215200ull * 1000000000ull);
    if (!f) return;
    if (f->fix == telltale::sensors::GnssFixKind::kNone) {
      FUZZ_CHECK(std::isnan(f->lat_deg) && std::isnan(f->lon_deg) && std::isnan(f->sog_m_s));
    } else {
      FUZZ_CHECK(std::fabs(f->lat_deg) <= 90.0 && std::fabs(f->lon_deg) <= 180.0);
      FUZZ_CHECK(!(f->sog_m_s > 30.0));
      FUZZ_CHECK(std::isnan(f->cog_deg) || f->sog_m_s >= 0.3);
    }
  };
  for (const std::string& l : lines) {
    t += 0.01;
    const auto r = telltale::sensors::parse_nmea_gnss(l, options);
    if (r.status != NmeaStatus::kOk) continue;
    check_gnss(r.gnss);
    if (auto done = epochs.add(r.gnss, t)) gate_check(*done);
  }
  if (auto done = epochs.flush_if_quiet(t + 1.0)) gate_check(*done);
}

/// A wind sentence: a reading in range, and the true wind made of it finite or NaN, never out of
/// range, on any boat velocity.
void wind_check(std::string_view line, const NmeaParseOptions& options, std::uint8_t seed) {
  const auto w = telltale::sensors::parse_nmea_wind(line, options);
  if (w.status != NmeaStatus::kOk) return;
  FUZZ_CHECK(w.reading.angle_deg >= 0.0 && w.reading.angle_deg <= 360.0);
  FUZZ_CHECK(std::isnan(w.reading.speed_m_s) ||
             (w.reading.speed_m_s >= 0.0 && w.reading.speed_m_s <= 100.0));
  const double sog = (seed & 1) ? std::nan("") : seed * 0.1,
               cog = (seed & 2) ? std::nan("") : seed * 1.7;
  const auto t = telltale::fusion::true_wind(w.reading, (seed & 4) ? std::nan("") : seed * 1.3, sog,
                                             cog, (seed & 8) ? std::nan("") : 2.5);
  FUZZ_CHECK(std::isnan(t.from_deg) || (t.from_deg >= 0.0 && t.from_deg < 360.0));
  FUZZ_CHECK(std::isnan(t.speed_m_s) || t.speed_m_s >= 0.0);
}

struct Assembled {
  std::vector<std::string> lines;
  NmeaLineAssembler::Stats stats;
};

/// Feeds `bytes` in pieces whose lengths come from a small generator seeded by `seed` (0: whole).
Assembled assemble(std::string_view bytes, std::uint8_t seed, bool datagram) {
  NmeaLineAssembler a;
  Assembled out;
  const auto on_line = [&](std::string_view l) { out.lines.emplace_back(l); };
  telltale::fuzz::feed_in_pieces(bytes.size(), seed, 97, [&](std::size_t pos, std::size_t n) {
    a.feed(bytes.data() + pos, n, on_line);
  });
  if (datagram) a.end_of_record(on_line);
  out.stats = a.stats();
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  telltale::fuzz::Input in(data, size);
  const std::uint8_t mode = in.byte();
  const std::uint8_t seed = in.byte();
  NmeaParseOptions options;
  options.accept_missing_checksum = (mode & 1) != 0;
  const bool datagram = (mode & 2) != 0;
  const std::string_view bytes = in.rest();

  parse_and_check(bytes, options);
  if (const auto g = telltale::sensors::parse_nmea_gnss(bytes, options); g.status == NmeaStatus::kOk)
    check_gnss(g.gnss);

  const Assembled whole = assemble(bytes, 0, datagram);
  const Assembled cut = assemble(bytes, static_cast<std::uint8_t>(seed | 1), datagram);
  FUZZ_CHECK(whole.lines == cut.lines);
  FUZZ_CHECK(whole.stats.lines == cut.stats.lines && whole.stats.overlong == cut.stats.overlong &&
             whole.stats.truncated == cut.stats.truncated &&
             whole.stats.garbage_bytes == cut.stats.garbage_bytes);
  FUZZ_CHECK(whole.stats.lines == whole.lines.size());
  for (const std::string& l : whole.lines) {
    FUZZ_CHECK(!l.empty() && l[0] == '$' && l.size() <= kNmeaMaxLine);
    FUZZ_CHECK(l.find_first_of("\r\n") == std::string::npos);
    FUZZ_CHECK(l.find('$', 1) == std::string::npos);
    parse_and_check(l, options);
    wind_check(l, options, seed);
  }
  gnss_pipeline(whole.lines, options);
  return 0;
}
