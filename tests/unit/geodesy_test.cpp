#include "fusion/geodesy.hpp"

#include "odometry/error.hpp"

#include <gtest/gtest.h>

namespace gvio::fusion {
namespace {

// WGS84 reference values: a = 6378137 m, b = 6356752.314245 m.
TEST(Geodesy, EcefOfKnownPoints) {
  EXPECT_NEAR((llaToEcef({0, 0, 0}) - Eigen::Vector3d(6378137.0, 0, 0)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((llaToEcef({90, 0, 0}) - Eigen::Vector3d(0, 0, 6356752.314245)).norm(), 0.0, 1e-5);
  EXPECT_NEAR((llaToEcef({0, 90, 100}) - Eigen::Vector3d(0, 6378237.0, 0)).norm(), 0.0, 1e-6);
}

// Karlsruhe (KITTI) round trip to sub-millimetre.
TEST(Geodesy, EcefRoundTrip) {
  const Lla p{48.98253, 8.39035, 116.4};
  const Lla q = ecefToLla(llaToEcef(p));
  EXPECT_NEAR(q.lat_deg, p.lat_deg, 1e-10);
  EXPECT_NEAR(q.lon_deg, p.lon_deg, 1e-10);
  EXPECT_NEAR(q.h_ellipsoid_m, p.h_ellipsoid_m, 1e-6);
}

TEST(Geodesy, EnuAxes) {
  const EnuFrame enu({48.98253, 8.39035, 116.4});
  EXPECT_NEAR(enu.toEnu({48.98253, 8.39035, 116.4}).norm(), 0.0, 1e-6);
  // One arc-second of latitude is ~30.9 m north at this latitude (meridian radius ~6.37e6 m).
  const Eigen::Vector3d north = enu.toEnu({48.98253 + 1.0 / 3600.0, 8.39035, 116.4});
  EXPECT_NEAR(north.x(), 0.0, 1e-3);
  EXPECT_NEAR(north.y(), 30.89, 0.02);
  EXPECT_LT(std::abs(north.z()), 1e-3);
  const Eigen::Vector3d east = enu.toEnu({48.98253, 8.39035 + 1.0 / 3600.0, 116.4});
  EXPECT_NEAR(east.x(), 20.34, 0.02);  // 30.92 m x cos(48.98 deg)
  EXPECT_NEAR(east.y(), 0.0, 1e-3);
  const Eigen::Vector3d up = enu.toEnu({48.98253, 8.39035, 126.4});
  EXPECT_NEAR((up - Eigen::Vector3d(0, 0, 10)).norm(), 0.0, 1e-6);
}

TEST(Geodesy, EnuRoundTrip) {
  const EnuFrame enu({-33.8688, 151.2093, 50.0});
  const Eigen::Vector3d p(1234.5, -987.25, 12.0);
  EXPECT_NEAR((enu.toEnu(enu.toLla(p)) - p).norm(), 0.0, 1e-6);
}

TEST(Geodesy, ValidLla) {
  EXPECT_TRUE(isValidLla({45, 90, 0}));
  EXPECT_FALSE(isValidLla({91, 0, 0}));
  EXPECT_FALSE(isValidLla({0, -181, 0}));
  EXPECT_FALSE(isValidLla({0, 0, std::nan("")}));
}

// Reference values from PROJ, an independent implementation:
//   echo "48.98253 8.39035" | cs2cs -f "%.3f" EPSG:4326 EPSG:32632  -> 455393.182 5425692.788
//   echo "-33.8688 151.2093" | cs2cs -f "%.3f" EPSG:4326 EPSG:32756 -> 334368.634 6250948.345
// EPSG codes by definition (WGS 84 / UTM zone NN N = 326NN, S = 327NN).
TEST(Geodesy, UtmOfKnownPoints) {
  const Utm k = llaToUtm({48.98253, 8.39035, 116.4});
  EXPECT_EQ(k.zone, 32);
  EXPECT_TRUE(k.north);
  EXPECT_EQ(k.epsg(), 32632);
  EXPECT_NEAR(k.easting_m, 455393.182, 0.01);
  EXPECT_NEAR(k.northing_m, 5425692.788, 0.01);
  const Utm s = llaToUtm({-33.8688, 151.2093, 0});  // Sydney
  EXPECT_EQ(s.zone, 56);
  EXPECT_FALSE(s.north);
  EXPECT_EQ(s.epsg(), 32756);
  EXPECT_NEAR(s.easting_m, 334368.634, 0.01);
  EXPECT_NEAR(s.northing_m, 6250948.345, 0.01);
  EXPECT_EQ(llaToUtm({60.0, 5.0, 0}).zone, 32);  // Norway exception: zone 32V is widened
}

TEST(Geodesy, UtmRoundTripAndForcedZone) {
  const Lla p{48.98253, 8.39035, 116.4};
  const Lla q = utmToLla(llaToUtm(p), p.h_ellipsoid_m);
  EXPECT_NEAR(q.lat_deg, p.lat_deg, 1e-9);
  EXPECT_NEAR(q.lon_deg, p.lon_deg, 1e-9);
  // A neighbouring zone still converts (with more scale error) and back.
  const Utm forced = llaToUtm(p, 31);
  EXPECT_EQ(forced.zone, 31);
  EXPECT_NEAR(utmToLla(forced, 0).lat_deg, p.lat_deg, 1e-9);
  EXPECT_THROW(llaToUtm({85.0, 0.0, 0.0}), InvalidInput);
  EXPECT_THROW(llaToUtm(p, 0), InvalidInput);
}

}  // namespace
}  // namespace gvio::fusion
