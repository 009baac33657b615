#pragma once
// Brute force for the chart tiers: every tier bucket of a boat holds exactly the count and the
// extremes a pass over that boat's stored samples finds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>

#include "store.hpp"

namespace telltale::shore {

inline void expect_tiers_hold(Store& store, const std::string& boat_id) {
  struct Expected {
    std::int64_t n = 0;
    double heel_lo = 1e9, heel_hi = -1e9, pitch_lo = 1e9, pitch_hi = -1e9;
  };
  for (const auto w : kTierWidths_s) {
    SCOPED_TRACE(boat_id + ", tier width " + std::to_string(w) + " s");
    const std::uint64_t w_ns = w * 1000000000ULL;
    std::map<std::uint64_t, Expected> want;
    store.visit_attitude(boat_id, 0, UINT64_MAX, [&](const AttitudeRow& r) {
      Expected& e = want[r.t_utc_ns / w_ns * w_ns];
      ++e.n;
      e.heel_lo = std::min(e.heel_lo, r.heel_deg);
      e.heel_hi = std::max(e.heel_hi, r.heel_deg);
      e.pitch_lo = std::min(e.pitch_lo, r.pitch_deg);
      e.pitch_hi = std::max(e.pitch_hi, r.pitch_deg);
      return true;
    });
    const auto got = store.attitude_tier(boat_id, w, 0, UINT64_MAX);
    ASSERT_EQ(got.size(), want.size());
    for (const auto& b : got) {
      ASSERT_EQ(want.count(b.start_ns), 1u) << b.start_ns;
      const Expected& e = want.at(b.start_ns);
      EXPECT_EQ(b.n, e.n) << b.start_ns;
      EXPECT_EQ(b.extremes[0].heel_deg, e.heel_lo) << b.start_ns;
      EXPECT_EQ(b.extremes[1].heel_deg, e.heel_hi) << b.start_ns;
      EXPECT_EQ(b.extremes[2].pitch_deg, e.pitch_lo) << b.start_ns;
      EXPECT_EQ(b.extremes[3].pitch_deg, e.pitch_hi) << b.start_ns;
      for (const auto& r : b.extremes) {
        EXPECT_GE(r.t_utc_ns, b.start_ns);
        EXPECT_LT(r.t_utc_ns, b.start_ns + w_ns);
      }
    }
  }
}

}  // namespace telltale::shore
