#include "mapping/map_correction.hpp"

#include <cmath>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include "odometry/error.hpp"

namespace gvio::mapping {

struct MapCorrection::Tree {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::KdTreeFLANN<pcl::PointXYZ> kd;  // z = 0: nearest in the plane
};

MapCorrection::MapCorrection(const std::vector<Eigen::Isometry3d>& T_old,
                             const std::vector<Eigen::Isometry3d>& T_new, double cell_m)
    : tree_(std::make_unique<Tree>()), cell_m_(cell_m) {
  if (T_old.empty() || T_old.size() != T_new.size()) {
    throw InvalidInput("map correction: the old and new keyframe poses differ in number");
  }
  if (!(std::isfinite(cell_m) && cell_m > 0.0)) {
    throw InvalidInput("map correction: the cell size must be > 0");
  }
  delta_.reserve(T_old.size());
  for (std::size_t k = 0; k < T_old.size(); ++k) {
    delta_.push_back(T_new[k] * T_old[k].inverse());
    tree_->cloud->push_back(pcl::PointXYZ(static_cast<float>(T_old[k].translation().x()),
                                          static_cast<float>(T_old[k].translation().y()), 0.0F));
  }
  tree_->kd.setInputCloud(tree_->cloud);
}

MapCorrection::~MapCorrection() = default;
MapCorrection::MapCorrection(MapCorrection&&) noexcept = default;
MapCorrection& MapCorrection::operator=(MapCorrection&&) noexcept = default;

std::size_t MapCorrection::keyframeAt(const Eigen::Vector3d& p) {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x() / cell_m_));
  const auto iy = static_cast<std::int64_t>(std::floor(p.y() / cell_m_));
  // 32 bits per axis: +-4e9 cells of 2 m, far beyond any map.
  const std::uint64_t key =
      (static_cast<std::uint64_t>(ix) << 32) ^ (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
  const auto it = cells_.find(key);
  if (it != cells_.end()) return it->second;
  const pcl::PointXYZ centre(static_cast<float>((static_cast<double>(ix) + 0.5) * cell_m_),
                             static_cast<float>((static_cast<double>(iy) + 0.5) * cell_m_), 0.0F);
  std::vector<int> index(1);
  std::vector<float> sq(1);
  std::uint32_t k = 0;
  if (tree_->kd.nearestKSearch(centre, 1, index, sq) == 1) k = static_cast<std::uint32_t>(index[0]);
  cells_.emplace(key, k);
  return k;
}

Eigen::Vector3d MapCorrection::apply(const Eigen::Vector3d& p) {
  return delta_[keyframeAt(p)] * p;
}

}  // namespace gvio::mapping
