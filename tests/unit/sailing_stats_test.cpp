// Heel against speed and the wind read from a track (shore_server/sailing_stats.hpp).
#include "sailing_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace telltale::shore {
namespace {

/// A beat and a run in a wind from `wind_from`: upwind at 42 deg, heeling to leeward (port tack
/// heels to starboard, +), 2.5 m/s at 10-15 deg of heel and 3 m/s at 5-10; downwind gybing at 150
/// deg, 4 m/s, heel +-2; a reach, a stop and a time without a fix.
std::vector<SailingPoint> race(double wind_from, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<SailingPoint> pts;
  const auto add = [&](double seconds, double cog, double heel, double sog) {
    for (int i = 0; i < static_cast<int>(seconds * 25); ++i)
      pts.push_back({0.04, heel + 0.3 * n(rng), sog, std::fmod(cog + 2.0 * n(rng) + 720.0, 360.0)});
  };
  for (int leg = 0; leg < 3; ++leg) {
    add(60, wind_from - 42, -12.0, 2.5);  // starboard tack, heeled to port
    add(60, wind_from + 42, 12.0, 2.5);   // port tack, heeled to starboard
    add(30, wind_from - 42, -7.0, 3.0);
    add(30, wind_from + 42, 7.0, 3.0);
    add(90, wind_from + 180 + 30, -2.0, 4.0);  // downwind, starboard gybe
    add(90, wind_from + 180 - 30, 2.0, 4.0);
  }
  add(20, wind_from + 90, 5.0, 4.5);  // a reach
  add(10, 0.0, 0.0, 0.1);             // stopped
  for (int i = 0; i < 250; ++i) pts.push_back({0.04, 3.0, std::nan(""), std::nan("")});
  return pts;
}

double band_sog(const HeelSpeed::Bands& bands, double heel) {
  for (const auto& b : bands)
    if (heel >= b.from_deg && heel < b.to_deg) return b.mean_sog_m_s;
  return std::nan("");
}

TEST(HeelSpeed, TheWindIsReadFromTheTrackUpwindToldFromDownwindByTheHeel) {
  for (double wind : {0.0, 75.0, 255.0, 330.0}) {
    const auto w = estimate_wind_from_deg(race(wind, 3));
    ASSERT_TRUE(w) << wind;
    const double err = std::abs(std::fmod(*w - wind + 540.0, 360.0) - 180.0);
    EXPECT_LT(err, 4.0) << "wind " << wind << " read as " << *w;
  }
}

TEST(HeelSpeed, NoBeatNoWind) {
  std::vector<SailingPoint> reach(1000, {0.04, 5.0, 4.0, 90.0});
  EXPECT_FALSE(estimate_wind_from_deg(reach));
  const HeelSpeed hs = heel_speed(reach, std::nullopt);
  EXPECT_FALSE(hs.wind_from_deg);
  EXPECT_NEAR(hs.unsplit_s, 40.0, 1e-9);
}

TEST(HeelSpeed, MeanSpeedPerHeelBandPerPointOfSailingAndTheBandsSumToTheSession) {
  const auto pts = race(255.0, 5);
  const HeelSpeed hs = heel_speed(pts, std::nullopt);
  ASSERT_TRUE(hs.wind_from_deg);
  EXPECT_TRUE(hs.wind_estimated);
  // Starboard tack heels to port: its fast band is -10..-5, its slow one -15..-10.
  EXPECT_NEAR(band_sog(hs.upwind_starboard, -12.0), 2.5, 1e-9);
  EXPECT_NEAR(band_sog(hs.upwind_starboard, -7.0), 3.0, 1e-9);
  EXPECT_NEAR(band_sog(hs.upwind_port, 12.0), 2.5, 1e-9);
  EXPECT_NEAR(band_sog(hs.upwind_port, 7.0), 3.0, 1e-9);
  EXPECT_NEAR(band_sog(hs.downwind_starboard, -2.0), 4.0, 1e-9);
  EXPECT_TRUE(std::isnan(band_sog(hs.upwind_port, -12.0))) << "no time there";
  double banded = 0.0;
  for (const auto* g : {&hs.upwind_port, &hs.upwind_starboard, &hs.downwind_port,
                        &hs.downwind_starboard})
    for (const auto& b : *g) banded += b.seconds;
  EXPECT_NEAR(banded, 3 * (60 + 60 + 30 + 30 + 90 + 90), 0.5);
  EXPECT_NEAR(hs.reaching_s, 20.0, 0.5);
  EXPECT_NEAR(hs.slow_s, 10.0, 1e-6);
  EXPECT_NEAR(hs.no_fix_s, 10.0, 1e-6);
  EXPECT_NEAR(banded + hs.reaching_s + hs.slow_s + hs.no_fix_s + hs.unsplit_s, hs.total_s, 1e-6);
  double total = 0.0;
  for (const auto& p : pts) total += p.dt_s;
  EXPECT_NEAR(hs.total_s, total, 1e-6);
  // The coach's wind wins over the estimate.
  const HeelSpeed given = heel_speed(pts, 255.0);
  EXPECT_FALSE(given.wind_estimated);
  EXPECT_DOUBLE_EQ(*given.wind_from_deg, 255.0);
}

}  // namespace
}  // namespace telltale::shore
