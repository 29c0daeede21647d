// Dense fusion across tiles: the global VoxelGrid keeps one point per voxel also where tiles
// meet, StatisticalOutlierRemoval removes isolated points but not the surface at tile borders,
// and repeated compaction of a tile gives the same voxels as one VoxelGrid.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>
#include <set>
#include <tuple>

#include "mapping/dense_fusion.hpp"

namespace gvio::mapping {
namespace {

pcl::PointXYZI point(double x, double y, double z) {
  pcl::PointXYZI p;
  p.x = static_cast<float>(x);
  p.y = static_cast<float>(y);
  p.z = static_cast<float>(z);
  p.intensity = 100.0f;
  return p;
}

// PCL VoxelGrid's cell of a point (float arithmetic, as PCL computes it).
std::tuple<long, long, long> voxelOf(float x, float y, float z, double leaf) {
  const float inv = 1.0f / static_cast<float>(leaf);
  return {static_cast<long>(std::floor(x * inv)), static_cast<long>(std::floor(y * inv)),
          static_cast<long>(std::floor(z * inv))};
}

TEST(MappingDenseFusion, OutliersGoSurfaceAtTileBordersStays) {
  // 0.1 m voxels: tiles are 51.2 m cubes, borders at x = 0 and x = +-51.2.
  // A strict SOR (1 sigma) that removes a fair share of any surface: points near a tile border
  // must not be removed more often than elsewhere.
  DenseFusion fusion(0.1, 20, 1.0);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> x(-60.0, 60.0), y(0.0, 3.0), up(1.0, 3.0);
  CameraCloud surface, outliers;
  for (int i = 0; i < 150000; ++i) {
    const double px = x(rng), py = y(rng);
    surface.push_back(point(px, py, 0.0));
  }
  for (int i = 0; i < 60; ++i) {
    // Isolated points, a third of them right at a tile border.
    const double px = i % 3 == 0 ? (i % 2 == 0 ? 0.02 : 51.17) : x(rng);
    const double py = y(rng), pz = up(rng);
    outliers.push_back(point(px, py, pz));
  }
  // Two keyframes' worth of the surface: the second pass lands in the same voxels.
  fusion.add(surface);
  fusion.add(surface);
  fusion.add(outliers);
  EXPECT_EQ(fusion.pointsAdded(), 2 * surface.size() + outliers.size());
  const MapCloud map = fusion.finish();

  std::set<std::tuple<long, long, long>> surface_voxels;
  for (const auto& p : surface) surface_voxels.insert(voxelOf(p.x, p.y, p.z, 0.1));
  EXPECT_EQ(fusion.pointsAfterVoxel(), surface_voxels.size() + outliers.size());

  const auto near_border = [](float px) {
    return std::abs(px) < 0.2f || std::abs(px - 51.2f) < 0.2f || std::abs(px + 51.2f) < 0.2f;
  };
  std::size_t border_voxels = 0;
  for (const auto& v : surface_voxels) {
    if (near_border((static_cast<float>(std::get<0>(v)) + 0.5f) * 0.1f)) ++border_voxels;
  }
  std::size_t kept_outliers = 0, kept_border = 0;
  std::set<std::tuple<long, long, long>> voxels;
  for (const auto& p : map) {
    if (p.z > 0.5f) ++kept_outliers;
    if (near_border(p.x)) ++kept_border;
    voxels.insert(voxelOf(p.x, p.y, p.z, 0.1));
    EXPECT_EQ(p.source, 1);
  }
  EXPECT_EQ(kept_outliers, 0u);
  EXPECT_EQ(voxels.size(), map.size());  // one point per voxel, also across tile borders
  // Without the neighbouring tiles' points, points near a border would lack half their
  // neighbours and be removed more often.
  const double kept_all = static_cast<double>(map.size()) / surface_voxels.size();
  const double kept_near = static_cast<double>(kept_border) / border_voxels;
  std::cout << "kept " << kept_all << " overall, " << kept_near << " near borders\n";
  EXPECT_GT(kept_all, 0.6);
  EXPECT_GT(kept_near, 0.95 * kept_all);
}

TEST(MappingDenseFusion, RepeatedCompactionKeepsTheVoxels) {
  DenseFusion fusion(0.1, 20, 3.0);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> xy(0.5, 10.5);
  std::set<std::tuple<long, long, long>> voxels;
  // 1.2 M points on 100 m^2: the tile is voxelised whenever it doubles (first at 500 k).
  for (int batch = 0; batch < 6; ++batch) {
    CameraCloud cloud;
    for (int i = 0; i < 200000; ++i) {
      const double px = xy(rng), py = xy(rng);
      cloud.push_back(point(px, py, 1.05));
      voxels.insert(voxelOf(cloud.back().x, cloud.back().y, cloud.back().z, 0.1));
    }
    fusion.add(cloud);
  }
  const MapCloud map = fusion.finish();
  EXPECT_EQ(fusion.pointsAfterVoxel(), voxels.size());
  EXPECT_GT(map.size(), voxels.size() * 95 / 100);
  EXPECT_TRUE(fusion.finish().empty());  // finish() hands everything over
}

}  // namespace
}  // namespace gvio::mapping
