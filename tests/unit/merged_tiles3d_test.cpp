// gvio export --to 3dtiles on a merged map (app/fleet/merged_tiles3d.hpp): every tile's point in
// ECEF within a millimetre of GeographicLib's own conversion of its UTM coordinates, with its
// drive and intensity; other formats refused in one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <cstring>
#include <nlohmann/json.hpp>

#include "support/fixtures.hpp"
#include "support/tiles3d_reader.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

constexpr double kOriginE = 455393.18, kOriginN = 5425692.79, kOriginH = 116.4;  // UTM 32N

struct MapPoint {
  float x, y, z, intensity;
  std::uint16_t drive;
};

// Two tiles of a merge folder as gvio merge writes them (the fields gvio reads).
std::vector<MapPoint> writeMergedMap(const fs::path& dir) {
  fs::create_directories(dir / "tiles");
  std::vector<MapPoint> all;
  nlohmann::json tiles = nlohmann::json::array();
  for (int t = 0; t < 2; ++t) {
    std::vector<MapPoint> pts;
    for (int i = 0; i < 400; ++i) {
      const double a = 0.05 * i;
      pts.push_back({static_cast<float>(t * 900.0 + 3.0 * i),
                     static_cast<float>(40.0 * std::sin(a)), static_cast<float>(0.02 * i),
                     static_cast<float>(i % 256), static_cast<std::uint16_t>(t + 1)});
    }
    pcl::PCLPointCloud2 cloud;
    const auto field = [](const std::string& name, std::uint32_t offset, std::uint8_t type) {
      pcl::PCLPointField f;
      f.name = name;
      f.offset = offset;
      f.datatype = type;
      f.count = 1;
      return f;
    };
    using F = pcl::PCLPointField;
    cloud.fields = {field("x", 0, F::FLOAT32),
                    field("y", 4, F::FLOAT32),
                    field("z", 8, F::FLOAT32),
                    field("intensity", 12, F::FLOAT32),
                    field("point_source_id", 16, F::UINT16),
                    field("source", 18, F::UINT8)};
    cloud.point_step = 20;
    cloud.width = static_cast<std::uint32_t>(pts.size());
    cloud.height = 1;
    cloud.row_step = cloud.point_step * cloud.width;
    cloud.data.assign(cloud.row_step, 0);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      std::uint8_t* o = cloud.data.data() + 20 * k;
      std::memcpy(o, &pts[k], 16);
      std::memcpy(o + 16, &pts[k].drive, 2);
      o[18] = 1;
    }
    const std::string name = "T" + std::to_string(t);
    pcl::PCDWriter writer;
    EXPECT_EQ(writer.writeBinary((dir / "tiles" / (name + ".pcd")).string(), cloud), 0);
    tiles.push_back({{"name", name},
                     {"sw_easting_m", kOriginE + t * 900.0},
                     {"sw_northing_m", kOriginN - 50.0},
                     {"points", pts.size()},
                     {"files", {{"pcd", "tiles/" + name + ".pcd"}}}});
    all.insert(all.end(), pts.begin(), pts.end());
  }
  const nlohmann::json index = {
      {"crs", {{"epsg", 32632}, {"utm_zone", 32}, {"north", true}}},
      {"drives",
       {{{"name", "a"}, {"point_source_id", 1}}, {{"name", "b"}, {"point_source_id", 2}}}},
      {"map_frame",
       {{"origin_easting_m", kOriginE},
        {"origin_northing_m", kOriginN},
        {"origin_h_ellipsoid_m", kOriginH}}},
      {"tile_size_m", 900.0},
      {"tiles", tiles}};
  writeText(dir / "tiles.json", index.dump(1));
  return all;
}

TEST(MergedTiles3d, EveryPointInEcefWithItsDrive) {
  const TempDir dir("mergedtiles");
  const std::vector<MapPoint> pts = writeMergedMap(dir.path() / "map");
  const auto r = runGvio("export --run " + quoted(dir.path() / "map") + " --to 3dtiles");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("800 points"));
  const Tileset ts = readTileset(dir.path() / "map" / "3dtiles");
  std::vector<Eigen::Vector3d> got;
  std::vector<std::uint16_t> drive, intensity;
  for (const auto& tile : ts.tiles) {
    got.insert(got.end(), tile.content.p_ecef.begin(), tile.content.p_ecef.end());
    drive.insert(drive.end(), tile.content.drive_id.begin(), tile.content.drive_id.end());
    intensity.insert(intensity.end(), tile.content.intensity.begin(), tile.content.intensity.end());
  }
  ASSERT_EQ(got.size(), pts.size());
  const GeographicLib::Geocentric& earth = GeographicLib::Geocentric::WGS84();
  std::size_t matched = 0;
  for (const MapPoint& p : pts) {
    double lat = 0, lon = 0;
    GeographicLib::UTMUPS::Reverse(32, true, kOriginE + double{p.x}, kOriginN + double{p.y}, lat,
                                   lon);
    Eigen::Vector3d ecef;
    earth.Forward(lat, lon, kOriginH + double{p.z}, ecef.x(), ecef.y(), ecef.z());
    for (std::size_t k = 0; k < got.size(); ++k) {
      if ((got[k] - ecef).norm() < 0.001) {
        EXPECT_EQ(drive[k], p.drive);
        EXPECT_EQ(intensity[k], static_cast<std::uint16_t>(p.intensity) * 257);
        ++matched;
        break;
      }
    }
  }
  EXPECT_EQ(matched, pts.size()) << "points farther than 1 mm from GeographicLib's ECEF";
  const auto las = runGvio("export --run " + quoted(dir.path() / "map") + " --to las");
  EXPECT_EQ(las.exit_code, 2);
  EXPECT_THAT(las.err, HasSubstr("is a merged map"));
}

}  // namespace
}  // namespace gvio::test
