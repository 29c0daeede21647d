// LAS 1.4 writer: read back with the tests' own reader (support/las_reader), coordinates against
// GeographicLib's LocalCartesian + UTMUPS called directly, and a published UTM coordinate.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <random>

#include "export/las_writer.hpp"
#include "io/input_error.hpp"
#include "support/fixtures.hpp"
#include "support/las_reader.hpp"

namespace gvio::test {
namespace {
using exporter::LasPoint;
using testing::HasSubstr;

// UTM of a local ENU point in a given zone, straight from GeographicLib (no gvio code).
Eigen::Vector3d referenceUtm(const fusion::Lla& origin, const Eigen::Vector3d& p_enu, int zone) {
  const GeographicLib::LocalCartesian enu(origin.lat_deg, origin.lon_deg, origin.h_ellipsoid_m);
  double lat = 0, lon = 0, h = 0;
  enu.Reverse(p_enu.x(), p_enu.y(), p_enu.z(), lat, lon, h);
  int used_zone = 0;
  bool north = true;
  double x = 0, y = 0;
  GeographicLib::UTMUPS::Forward(lat, lon, used_zone, north, x, y, zone);
  return {x, y, h};
}

std::vector<LasPoint> randomPoints(int n, double extent_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-extent_m, extent_m), z(-5.0, 30.0);
  std::vector<LasPoint> points;
  for (int i = 0; i < n; ++i) {
    LasPoint p;
    p.p_enu = {xy(rng), xy(rng), z(rng)};
    p.intensity = static_cast<std::uint16_t>(rng() % 65536);
    p.classification = static_cast<std::uint8_t>(rng() % 20);
    p.point_source_id = static_cast<std::uint16_t>(rng() % 65536);
    points.push_back(p);
  }
  return points;
}

TEST(ExportLas, HeaderVlrAndPointsReadBackAsWritten) {
  TempDir dir("las");
  const fusion::Lla origin{49.011, 8.4, 112.5};  // Karlsruhe: UTM zone 32N
  const auto points = randomPoints(500, 400.0, 7);
  const auto summary = exporter::writeLas(dir.path() / "map.las", origin, points);
  EXPECT_EQ(summary.crs.zone, 32);
  EXPECT_TRUE(summary.crs.north);

  const LasFile las = readLas(dir.path() / "map.las");
  EXPECT_EQ(las.signature, "LASF");
  EXPECT_EQ(las.version_major, 1);
  EXPECT_EQ(las.version_minor, 4);
  EXPECT_EQ(las.header_size, 375);
  EXPECT_EQ(las.point_format, 6);
  EXPECT_EQ(las.point_length, 30);
  EXPECT_NE(las.global_encoding & 0x10, 0) << "WKT bit";
  EXPECT_EQ(las.point_count, 500U);
  EXPECT_EQ(las.by_return[0], 500U);
  EXPECT_EQ(las.legacy_point_count, 0U) << "must be 0 for point formats >= 6";
  EXPECT_EQ(las.evlr_count, 0U);
  EXPECT_THAT(las.generating_software, HasSubstr("gvio"));
  EXPECT_EQ(las.scale, Eigen::Vector3d::Constant(0.001));

  ASSERT_EQ(las.vlr_count, 1U);
  EXPECT_EQ(las.vlrs[0].user_id, "LASF_Projection");
  EXPECT_EQ(las.vlrs[0].record_id, 2112);
  EXPECT_EQ(las.vlrs[0].data.back(), '\0');
  EXPECT_THAT(las.wkt(), HasSubstr("UTM zone 32N"));
  EXPECT_THAT(las.wkt(), HasSubstr("AUTHORITY[\"EPSG\",\"32632\"]"));

  ASSERT_EQ(las.points.size(), points.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  double worst_m = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d expected = referenceUtm(origin, points[i].p_enu, 32);
    worst_m = std::max(worst_m, (las.points[i].xyz - expected).cwiseAbs().maxCoeff());
    EXPECT_EQ(las.points[i].intensity, points[i].intensity);
    EXPECT_EQ(las.points[i].classification, points[i].classification);
    EXPECT_EQ(las.points[i].point_source_id, points[i].point_source_id);
    EXPECT_EQ(las.points[i].return_number, 1);
    EXPECT_EQ(las.points[i].number_of_returns, 1);
    lo = lo.cwiseMin(las.points[i].xyz);
    hi = hi.cwiseMax(las.points[i].xyz);
  }
  EXPECT_LE(worst_m, 0.0005 + 1e-9) << "quantisation at 1 mm rounds to within half a step";
  EXPECT_LT((las.min - lo).norm(), 1e-9);
  EXPECT_LT((las.max - hi).norm(), 1e-9);
  EXPECT_LT((las.offset - 0.5 * (lo + hi)).cwiseAbs().maxCoeff(), 1.0) << "offset near the data";
}

// Wikipedia's UTM example: the CN Tower, 43°38'33.24"N 79°23'13.7"W, is at 630084 m E,
// 4833438 m N in zone 17 (metre-rounded), and GeographicLib to the millimetre.
TEST(ExportLas, KnownLatLonLandsOnItsPublishedUtm) {
  TempDir dir("las_known");
  const fusion::Lla cn_tower{43.0 + 38.0 / 60 + 33.24 / 3600, -(79.0 + 23.0 / 60 + 13.7 / 3600),
                             100.0};
  const std::vector<LasPoint> points = {LasPoint{}, LasPoint{{100.0, -50.0, 3.0}, 0, 0}};
  const auto summary = exporter::writeLas(dir.path() / "cn.las", cn_tower, points);
  EXPECT_EQ(summary.crs.epsg(), 32617);
  const LasFile las = readLas(dir.path() / "cn.las");
  ASSERT_EQ(las.points.size(), 2U);
  EXPECT_NEAR(las.points[0].xyz.x(), 630084.0, 1.0);
  EXPECT_NEAR(las.points[0].xyz.y(), 4833438.0, 1.0);
  EXPECT_NEAR(las.points[0].xyz.z(), 100.0, 0.001);
  for (std::size_t i = 0; i < 2; ++i) {
    const Eigen::Vector3d expected = referenceUtm(cn_tower, points[i].p_enu, 17);
    EXPECT_LT((las.points[i].xyz - expected).cwiseAbs().maxCoeff(), 0.001) << i;
  }
  EXPECT_THAT(las.wkt(), HasSubstr("UTM zone 17N"));
}

TEST(ExportLas, SouthernHemisphereAndForcedZone) {
  TempDir dir("las_zone");
  const fusion::Lla sydney{-33.8568, 151.2153, 40.0};
  exporter::writeLas(dir.path() / "s.las", sydney, randomPoints(20, 100.0, 3));
  EXPECT_THAT(readLas(dir.path() / "s.las").wkt(), HasSubstr("UTM zone 56S"));

  // 11.99 E lies in zone 32; a map reaching past 12 E stays in the forced zone 32 throughout.
  const fusion::Lla border{48.0, 11.999, 500.0};
  const auto points = randomPoints(50, 2000.0, 5);
  exporter::LasOptions options;
  options.utm_zone = 32;
  exporter::writeLas(dir.path() / "b.las", border, points, options);
  const LasFile las = readLas(dir.path() / "b.las");
  EXPECT_THAT(las.wkt(), HasSubstr("UTM zone 32N"));
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT((las.points[i].xyz - referenceUtm(border, points[i].p_enu, 32)).norm(), 0.001);
  }
}

TEST(ExportLas, BadInput) {
  TempDir dir("las_bad");
  const fusion::Lla origin{49.0, 8.4, 100.0};
  EXPECT_THROW(exporter::writeLas("/nonexistent/dir/x.las", origin, randomPoints(3, 1.0, 1)),
               io::InputError);
  exporter::LasOptions fine;
  fine.scale_m = 1e-6;  // 2^31 steps of 1 um: +-2.1 km
  EXPECT_THROW(exporter::writeLas(dir.path() / "x.las", origin, randomPoints(50, 5000.0, 1), fine),
               InvalidInput);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.las"));
  EXPECT_THROW(exporter::writeLas(dir.path() / "x.las", fusion::Lla{85.0, 0.0, 0.0}, {}),
               InvalidInput);  // beyond UTM's latitude band
}

}  // namespace
}  // namespace gvio::test
