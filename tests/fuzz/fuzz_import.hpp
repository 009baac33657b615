#pragma once
/// \file
/// What every import parser's fuzz target checks: no exception, no crash, and every point and
/// result within the record's contract (record.hpp): a time, a position whole or absent and in
/// range, speeds not negative, courses and headings in [0, 360), heel within ±180 and pitch
/// within ±90, and a result whose status agrees with what came out. Parsing twice gives the same.
/// Format detection and the VTK serial lookup (a default boat id) run on every input too.

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

#include "detect.hpp"
#include "fuzz_support.hpp"
#include "record.hpp"
#include "vtk.hpp"

namespace telltale::fuzz {

struct CheckingSink : shore::import::ImportSink {
  std::uint64_t points = 0, events = 0;
  double sum = 0.0;  ///< a digest of what came out, for the determinism check
  void point(const shore::import::ImportPoint& p) override {
    FUZZ_CHECK(p.t_utc_ns > 0);
    FUZZ_CHECK(std::isnan(p.lat_deg) == std::isnan(p.lon_deg));
    FUZZ_CHECK(std::isnan(p.lat_deg) || std::fabs(p.lat_deg) <= 90.0);
    FUZZ_CHECK(std::isnan(p.lon_deg) || std::fabs(p.lon_deg) <= 180.0);
    FUZZ_CHECK(std::isnan(p.sog_m_s) || (p.sog_m_s >= 0.0 && std::isfinite(p.sog_m_s)));
    FUZZ_CHECK(std::isnan(p.cog_deg) || (p.cog_deg >= 0.0 && p.cog_deg < 360.0));
    FUZZ_CHECK(std::isnan(p.heading_deg) || (p.heading_deg >= 0.0 && p.heading_deg < 360.0));
    FUZZ_CHECK(std::isnan(p.heel_deg) || std::fabs(p.heel_deg) <= 180.0);
    FUZZ_CHECK(std::isnan(p.pitch_deg) || std::fabs(p.pitch_deg) <= 90.0);
    ++points;
    sum += static_cast<double>(p.t_utc_ns % 1000003);
  }
  void event(const shore::import::ImportEvent& e) override {
    FUZZ_CHECK(!e.kind.empty());
    ++events;
  }
};

inline void fuzz_parser(shore::import::Format format, const std::uint8_t* data, std::size_t size) {
  using shore::import::ParseStatus;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string_view head = std::string_view(bytes).substr(0, shore::import::kDetectBytes);
  (void)shore::import::detect_format(head);
  if (const auto serial = shore::import::vtk_serial_number(head)) FUZZ_CHECK(*serial > 0);
  CheckingSink a, b;
  std::istringstream in_a(bytes), in_b(bytes);
  const auto ra = shore::import::parse_log(format, in_a, {}, a);
  const auto rb = shore::import::parse_log(format, in_b, {}, b);
  FUZZ_CHECK(ra.points == a.points);
  FUZZ_CHECK(ra.events == a.events);
  FUZZ_CHECK(ra.status == rb.status && ra.message == rb.message && a.points == b.points &&
             a.sum == b.sum);
  switch (ra.status) {
    case ParseStatus::kOk:
      FUZZ_CHECK(ra.points > 0 && ra.message.empty());
      break;
    case ParseStatus::kPartial:
      FUZZ_CHECK(ra.points > 0 && !ra.message.empty());
      break;
    case ParseStatus::kError:
      FUZZ_CHECK(!ra.message.empty());
      break;
  }
}

}  // namespace telltale::fuzz
