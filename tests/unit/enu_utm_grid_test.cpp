// fusion::EnuToUtmGrid (the merge's fast ENU -> UTM) against the exact conversion, and the
// merge's zone rules (app/fleet/merge_inputs.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "fleet/merge_inputs.hpp"
#include "fusion/enu_utm_grid.hpp"
#include "odometry/error.hpp"

namespace gvio::test {
namespace {

TEST(EnuToUtmGrid, MatchesTheExactConversionWithinAMillimetreOverTenKilometres) {
  const fusion::Lla origin{48.98253, 8.39035, 116.4};
  fusion::EnuToUtmGrid grid(origin, 32, true);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> horizontal(-5000.0, 5000.0), up(-80.0, 120.0);
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d p{horizontal(rng), horizontal(rng), up(rng)};
    worst = std::max(worst, (grid.toUtm(p) - grid.exactUtm(p)).norm());
  }
  EXPECT_LT(worst, 1e-3);
  // The exact conversion itself: the ENU origin is the origin's UTM position.
  const fusion::Utm utm = fusion::llaToUtm(origin, 32);
  EXPECT_NEAR((grid.exactUtm(Eigen::Vector3d::Zero()) -
               Eigen::Vector3d(utm.easting_m, utm.northing_m, origin.h_ellipsoid_m))
                  .norm(),
              0.0, 1e-6);
  EXPECT_FALSE(grid.toUtm(Eigen::Vector3d(std::nan(""), 0, 0)).allFinite());
}

TEST(EnuToUtmGrid, ANeighbouringZoneAndTheOtherHemisphereKeepOneGrid) {
  // 12.1 deg E lies in zone 33; forced into zone 32 it continues zone 32's grid eastwards.
  const fusion::Lla east{48.5, 12.1, 300.0};
  fusion::EnuToUtmGrid grid(east, 32, true);
  EXPECT_GT(grid.toUtm(Eigen::Vector3d::Zero()).x(), 700000.0);
  // Just south of the equator in a northern grid: negative northing, not 10 000 km.
  fusion::EnuToUtmGrid south({-0.001, 9.0, 0.0}, 32, true);
  EXPECT_NEAR(south.toUtm(Eigen::Vector3d::Zero()).y(), -110.6, 0.5);
}

TEST(MergeZones, DistanceOutsideAZoneAndTheRunsItRefuses) {
  EXPECT_EQ(fleet::kmOutsideZone({48.98, 8.39, 0}, 32), 0.0);  // inside zone 32 (6..12 deg E)
  EXPECT_NEAR(fleet::kmOutsideZone({48.98, 12.1, 0}, 32),
              0.1 * 111.32 * std::cos(48.98 * M_PI / 180), 1e-6);
  EXPECT_NEAR(fleet::kmOutsideZone({0.0, -177.0, 0}, 60), 3.0 * 111.32, 1e-6);  // across 180 deg
  fleet::MergeRun a, b;
  a.name = "a";
  a.georef.enu_origin = {48.98, 8.39, 100};
  a.georef.utm_zone = 32;
  b.name = "b";
  b.georef.enu_origin = {48.98, 12.1, 100};
  b.georef.utm_zone = 33;
  fleet::MergeConfig config;
  const fleet::MergeFrame frame = fleet::chooseMergeFrame({a, b}, config);  // 7 km: reprojected
  EXPECT_EQ(frame.crs.zone, 32);
  EXPECT_EQ(frame.crs.epsg(), 32632);
  config.max_zone_distance_km = 5.0;
  EXPECT_THROW(fleet::chooseMergeFrame({a, b}, config), InvalidInput);
}

}  // namespace
}  // namespace gvio::test
