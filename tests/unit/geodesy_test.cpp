#include "fusion/geodesy.hpp"

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

}  // namespace
}  // namespace gvio::fusion
