#include "mapping/dense_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <pcl/filters/statistical_outlier_removal.h>

namespace gvio::mapping {
namespace {

constexpr double kTileVoxels = 512.0;               // 512^3 < 2^31: VoxelGrid's int32 voxel index
constexpr std::size_t kMinCompactPoints = 100'000;  // below this a tile is cheap to keep raw

// Points of neighbouring tiles closer than this to a tile count as SOR neighbours: well beyond
// the ~0.3 m that 20 neighbours span on a surface sampled at 0.1 m.
double marginOf(double voxel_size_m) {
  return std::max(1.0, 10.0 * voxel_size_m);
}

}  // namespace

DenseFusion::DenseFusion(double voxel_size_m, int sor_mean_k, double sor_stddev_mul)
    : voxel_size_m_(voxel_size_m),
      tile_size_m_(voxel_size_m * kTileVoxels),
      sor_mean_k_(sor_mean_k),
      sor_stddev_mul_(sor_stddev_mul) {}

DenseFusion::TileKey DenseFusion::tileOf(const pcl::PointXYZI& p) const {
  return {static_cast<std::int64_t>(std::floor(static_cast<double>(p.x) / tile_size_m_)),
          static_cast<std::int64_t>(std::floor(static_cast<double>(p.y) / tile_size_m_)),
          static_cast<std::int64_t>(std::floor(static_cast<double>(p.z) / tile_size_m_))};
}

DenseFusion::TilePoint DenseFusion::pack(const pcl::PointXYZI& p) {
  const float i = std::clamp(p.intensity, 0.0f, 255.0f);
  return {p.x, p.y, p.z, static_cast<std::uint8_t>(std::lround(i))};
}

pcl::PointXYZI DenseFusion::unpack(const TilePoint& t) {
  pcl::PointXYZI p;
  p.x = t.x, p.y = t.y, p.z = t.z;
  p.intensity = static_cast<float>(t.intensity);
  return p;
}

CameraCloud DenseFusion::toCloud(const std::vector<TilePoint>& points) {
  CameraCloud cloud;
  cloud.reserve(points.size());
  for (const TilePoint& t : points) cloud.push_back(unpack(t));
  return cloud;
}

void DenseFusion::add(const CameraCloud& points_map) {
  std::map<TileKey, Tile*> touched;
  for (const auto& p : points_map) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const TileKey key = tileOf(p);
    auto it = touched.find(key);
    if (it == touched.end()) it = touched.emplace(key, &tiles_[key]).first;
    it->second->points.push_back(pack(p));
    ++points_added_;
  }
  for (auto& [key, tile] : touched) {
    if (tile->points.size() >= std::max(kMinCompactPoints, tile->compacted_size * 3 / 2)) {
      compact(*tile);
    }
  }
}

void DenseFusion::compact(Tile& tile, bool final) const {
  const CameraCloud voxels = voxelDownsample(toCloud(tile.points), voxel_size_m_);
  std::vector<TilePoint> packed;
  // Room for the growth that triggers the next compaction, so the vector never doubles past it.
  packed.reserve(final ? voxels.size() : std::max(kMinCompactPoints, voxels.size() * 3 / 2) + 1);
  for (const auto& p : voxels) packed.push_back(pack(p));
  tile.points.swap(packed);
  tile.compacted_size = tile.points.size();
}

CameraCloud DenseFusion::withMargin(const TileKey& key) const {
  const Tile& own = tiles_.at(key);
  CameraCloud out = toCloud(own.points);
  const double margin = marginOf(voxel_size_m_);
  Eigen::Vector3d lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<double>(key[a]) * tile_size_m_ - margin;
    hi[a] = static_cast<double>(key[a] + 1) * tile_size_m_ + margin;
  }
  for (std::int64_t dx = -1; dx <= 1; ++dx) {
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
      for (std::int64_t dz = -1; dz <= 1; ++dz) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const auto it = tiles_.find({key[0] + dx, key[1] + dy, key[2] + dz});
        if (it == tiles_.end()) continue;
        for (const TilePoint& t : it->second.points) {
          const Eigen::Array3d q(t.x, t.y, t.z);
          if ((q >= lo.array()).all() && (q < hi.array()).all()) out.push_back(unpack(t));
        }
      }
    }
  }
  return out;
}

void DenseFusion::keepBorder(const TileKey& key, Tile& tile) const {
  const double margin = marginOf(voxel_size_m_);
  Eigen::Array3d lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<double>(key[static_cast<std::size_t>(a)]) * tile_size_m_ + margin;
    hi[a] = static_cast<double>(key[static_cast<std::size_t>(a)] + 1) * tile_size_m_ - margin;
  }
  std::vector<TilePoint> border;
  for (const TilePoint& t : tile.points) {
    const Eigen::Array3d q(t.x, t.y, t.z);
    if (!((q >= lo).all() && (q < hi).all())) border.push_back(t);
  }
  tile.points.swap(border);
}

MapCloud DenseFusion::finish() {
  points_after_voxel_ = 0;
  for (auto& [key, tile] : tiles_) {
    compact(tile, true);
    points_after_voxel_ += tile.points.size();
  }
  MapCloud out;
  out.reserve(points_after_voxel_);
  for (auto& [key, tile] : tiles_) {
    const std::size_t n_own = tile.points.size();
    if (n_own == 0) continue;
    const CameraCloud area = withMargin(key);
    CameraCloud kept;
    if (area.size() > static_cast<std::size_t>(sor_mean_k_)) {
      pcl::StatisticalOutlierRemoval<pcl::PointXYZI> sor;
      sor.setInputCloud(CameraCloud::ConstPtr(&area, [](const CameraCloud*) {}));
      // Only the tile's own points are classified; the margin points serve as neighbours.
      auto own = std::make_shared<pcl::Indices>(n_own);
      std::iota(own->begin(), own->end(), 0);
      sor.setIndices(own);
      sor.setMeanK(sor_mean_k_);
      sor.setStddevMulThresh(sor_stddev_mul_);
      sor.filter(kept);
    } else {
      kept = toCloud(tile.points);  // too few points for the statistic: nothing to compare with
    }
    for (const auto& p : kept) {
      out.push_back(makeMapPoint(p.x, p.y, p.z, p.intensity, 0, MapPointSource::kDenseStereo));
    }
    // Tiles still to come need only this tile's points near its faces as neighbours.
    keepBorder(key, tile);
  }
  tiles_.clear();
  return out;
}

}  // namespace gvio::mapping
