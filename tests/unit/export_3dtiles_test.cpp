// exporter::writeTiles3d read back by the tests' own 3D Tiles reader (support/tiles3d_reader):
// every point once, where it was to a millimetre, inside its tile's ECEF box, with its intensity
// and drive; the tree's geometric errors shrink to 0 at the leaves.
#include "export/tiles3d_writer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "io/input_error.hpp"
#include "odometry/error.hpp"
#include "support/fixtures.hpp"
#include "support/tiles3d_reader.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

const fusion::Lla kOrigin{35.1547, 136.9665, 48.0};  // Nagoya

// A 600 m street of points whose intensity and drive encode their index (to find them back).
std::vector<exporter::TilesPoint> street(std::size_t n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> along(-300.0, 300.0), across(-15.0, 15.0), up(-2, 10);
  std::vector<exporter::TilesPoint> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    p[i].p_enu = {along(rng), across(rng), up(rng)};
    p[i].intensity = static_cast<std::uint16_t>(i % 65536);
    p[i].drive_id = static_cast<std::uint16_t>(i / 65536);
  }
  return p;
}

TEST(Export3dTiles, EveryPointOnceInItsBoxToAMillimetre) {
  TempDir dir("tiles3d");
  const std::vector<exporter::TilesPoint> points = street(150'000);
  mapping::PointLodConfig lod;
  lod.grid_cells = 16;
  lod.max_points_per_node = 8'000;
  const exporter::Tiles3dSummary s = exporter::writeTiles3d(dir.path() / "t", kOrigin, points, lod);
  EXPECT_EQ(s.points, points.size());
  EXPECT_GE(s.depth, 2);

  const Tileset ts = readTileset(dir.path() / "t");
  EXPECT_EQ(ts.version, "1.0");
  ASSERT_FALSE(ts.tiles.empty());
  EXPECT_EQ(ts.tiles[0].refine, "ADD");
  EXPECT_EQ(static_cast<std::size_t>(std::count_if(ts.tiles.begin(), ts.tiles.end(),
                                                   [](auto& t) { return !t.uri.empty(); })),
            s.tiles);
  const fusion::EnuFrame enu(kOrigin);
  std::vector<int> seen(points.size(), 0);
  for (const TilesetTile& t : ts.tiles) {
    if (t.parent >= 0) {
      EXPECT_LT(t.geometric_error, ts.tiles[static_cast<std::size_t>(t.parent)].geometric_error);
    } else {
      EXPECT_LT(t.geometric_error, ts.geometric_error);
    }
    const PntsTile& c = t.content;
    ASSERT_EQ(c.intensity.size(), c.p_ecef.size()) << t.uri;
    ASSERT_EQ(c.drive_id.size(), c.p_ecef.size()) << t.uri;
    ASSERT_EQ(c.rgb.size(), c.p_ecef.size()) << t.uri;
    for (std::size_t k = 0; k < c.p_ecef.size(); ++k) {
      const std::size_t i = c.drive_id[k] * 65536u + c.intensity[k];
      ASSERT_LT(i, points.size());
      ++seen[i];
      EXPECT_LT((enu.ecefToEnu(c.p_ecef[k]) - points[i].p_enu).norm(), 1e-3) << t.uri;
      EXPECT_EQ(c.rgb[k][0], points[i].intensity >> 8);
      // In its own box and in every ancestor's.
      for (int a = static_cast<int>(&t - ts.tiles.data()); a >= 0;
           a = ts.tiles[static_cast<std::size_t>(a)].parent) {
        EXPECT_TRUE(boxContains(ts.tiles[static_cast<std::size_t>(a)].box, c.p_ecef[k], 1e-3));
      }
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i) ASSERT_EQ(seen[i], 1) << i;
}

TEST(Export3dTiles, ReplacesAnEarlierTilesetRefusesOtherFolders) {
  TempDir dir("tiles3d_replace");
  const std::vector<exporter::TilesPoint> points = street(1'000);
  const fs::path out = dir.path() / "t";
  exporter::writeTiles3d(out, kOrigin, points);
  writeText(out / "tiles" / "stale.pnts", "left from before");
  exporter::writeTiles3d(out, kOrigin, points);
  EXPECT_FALSE(fs::exists(out / "tiles" / "stale.pnts"));
  EXPECT_EQ(readTileset(out).tiles.size(), 1u);

  fs::create_directories(dir.path() / "other");
  writeText(dir.path() / "other" / "notes.txt", "mine");
  EXPECT_THROW(exporter::writeTiles3d(dir.path() / "other", kOrigin, points), io::InputError);
  EXPECT_TRUE(fs::exists(dir.path() / "other" / "notes.txt"));

  std::vector<exporter::TilesPoint> none(3);
  for (auto& p : none) p.p_enu.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(exporter::writeTiles3d(dir.path() / "n", kOrigin, none), InvalidInput);
  EXPECT_FALSE(fs::exists(dir.path() / "n"));
  for (const auto& e : fs::directory_iterator(dir.path())) {
    EXPECT_THAT(e.path().filename().string(), testing::Not(testing::HasSubstr("gvio-tmp")));
  }
}

}  // namespace
}  // namespace gvio::test
