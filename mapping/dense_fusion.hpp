#pragma once
// Fuses the dense points of many keyframes (already in the map frame) into one cloud: VoxelGrid at
// voxel_size_m, then StatisticalOutlierRemoval, with memory bounded by the map, not the drive.
//
// Points are binned into cubic tiles of 512 voxels a side. pcl::VoxelGrid indexes voxels with
// int32 and refuses (returns its input) when a cloud spans more than 2^31 voxels, which a
// 3.7 km drive at 0.1 m does; a tile never can. A tile is re-voxelised whenever it has grown by
// half since its last compaction (and holds 100 k points), so overlapping keyframes (each surface
// is seen by ~5 of them) never pile up. VoxelGrid's voxels are aligned to multiples of the leaf
// size, so re-voxelising merges into the same voxels (the centroid of centroids differs from the
// exact centroid by far less than a voxel). SOR runs per tile with the points of the neighbouring
// tiles within a margin as neighbours only, so tile borders do not look like sparse regions; once
// filtered, a tile keeps only that margin band for the tiles after it, so the fused map is held
// about once in memory.
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "mapping/map_point.hpp"
#include "mapping/stereo_depth.hpp"

namespace gvio::mapping {

class DenseFusion {
 public:
  DenseFusion(double voxel_size_m, int sor_mean_k, double sor_stddev_mul);

  // Adds points in the map frame (intensity 0..255).
  void add(const CameraCloud& points_map);

  // Voxelises every tile, removes statistical outliers, and returns the dense map cloud (source
  // kDenseStereo, observations 0). Counts are filled in. The fusion is empty afterwards.
  [[nodiscard]] MapCloud finish();

  [[nodiscard]] std::size_t pointsAdded() const { return points_added_; }
  [[nodiscard]] std::size_t pointsAfterVoxel() const { return points_after_voxel_; }

 private:
  using TileKey = std::array<std::int64_t, 3>;
  // A point as a tile keeps it: 16 bytes instead of pcl::PointXYZI's 32 (the tiles hold the whole
  // dense map until finish(): 14 M points on KITTI-00). Converted to PCL only per tile, when
  // VoxelGrid or SOR runs on it.
  struct TilePoint {
    float x = 0.0f, y = 0.0f, z = 0.0f;
    std::uint8_t intensity = 0;
  };
  struct Tile {
    std::vector<TilePoint> points;
    std::size_t compacted_size = 0;
  };

  [[nodiscard]] TileKey tileOf(const pcl::PointXYZI& p) const;
  [[nodiscard]] static TilePoint pack(const pcl::PointXYZI& p);
  [[nodiscard]] static pcl::PointXYZI unpack(const TilePoint& t);
  [[nodiscard]] static CameraCloud toCloud(const std::vector<TilePoint>& points);
  // `final`: no room is kept for growth (finish()).
  void compact(Tile& tile, bool final = false) const;
  [[nodiscard]] CameraCloud withMargin(const TileKey& key) const;
  // Drops the tile's points farther than the SOR margin from its faces (after its own SOR).
  void keepBorder(const TileKey& key, Tile& tile) const;

  double voxel_size_m_;
  double tile_size_m_;
  int sor_mean_k_;
  double sor_stddev_mul_;
  std::map<TileKey, Tile> tiles_;
  std::size_t points_added_ = 0;
  std::size_t points_after_voxel_ = 0;
};

}  // namespace gvio::mapping
