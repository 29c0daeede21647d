#include "mapping/occupancy_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

namespace gvio::mapping {
namespace {

// Below this many nodes (~3 MB) a tree is not worth a full update-and-prune pass.
constexpr std::size_t kMinCompactNodes = 200'000;

}  // namespace

OccupancyBuilder::OccupancyBuilder(const OccupancyConfig& config)
    : config_(config), color_tree_(std::make_unique<octomap::ColorOcTree>(config.resolution_m)) {}

void OccupancyBuilder::insert(const CameraCloud& points_map, const Eigen::Vector3d& origin_map) {
  if (points_map.empty()) return;
  octomap::Pointcloud scan;
  scan.reserve(points_map.size());
  for (const auto& p : points_map) scan.push_back(p.x, p.y, p.z);
  const octomap::point3d origin(static_cast<float>(origin_map.x()),
                                static_cast<float>(origin_map.y()),
                                static_cast<float>(origin_map.z()));

  // What insertPointCloud(scan, origin, max_range, lazy_eval = true, discretize = true) does,
  // keeping the occupied keys for the colours.
  octomap::KeySet free_cells, occupied_cells;
  color_tree_->computeDiscreteUpdate(scan, origin, free_cells, occupied_cells, config_.max_range_m);
  for (const auto& key : free_cells) color_tree_->updateNode(key, false, true);
  for (const auto& key : occupied_cells) color_tree_->updateNode(key, true, true);

  // Mean grey value of the scan's points in each occupied voxel, merged into the voxel's colour.
  struct Sum {
    double intensity = 0.0;
    int n = 0;
  };
  std::unordered_map<octomap::OcTreeKey, Sum, octomap::OcTreeKey::KeyHash> sums;
  for (const auto& p : points_map) {
    octomap::OcTreeKey key;
    if (!color_tree_->coordToKeyChecked(octomap::point3d(p.x, p.y, p.z), key)) continue;
    if (occupied_cells.count(key) == 0) continue;  // beyond the max range
    Sum& s = sums[key];
    s.intensity += static_cast<double>(p.intensity);
    ++s.n;
  }
  for (const auto& [key, s] : sums) {
    const double grey = std::clamp(std::round(s.intensity / s.n), 0.0, 255.0);
    const auto g = static_cast<std::uint8_t>(grey);
    color_tree_->averageNodeColor(key, g, g, g);
  }

  if (color_tree_->size() >= std::max(kMinCompactNodes, nodes_after_compact_ * 3 / 2)) compact();
}

void OccupancyBuilder::compact() {
  color_tree_->updateInnerOccupancy();
  color_tree_->prune();
  nodes_after_compact_ = color_tree_->size();
}

OccupancyBuilder::Trees OccupancyBuilder::finish() {
  compact();
  Trees trees;
  trees.occupancy = maximumLikelihoodOcTree(*color_tree_);
  trees.color = std::move(color_tree_);
  color_tree_ = std::make_unique<octomap::ColorOcTree>(config_.resolution_m);
  nodes_after_compact_ = 0;
  return trees;
}

std::unique_ptr<octomap::OcTree> maximumLikelihoodOcTree(const octomap::ColorOcTree& tree) {
  auto ml = std::make_unique<octomap::OcTree>(tree.getResolution());
  ml->setOccupancyThres(tree.getOccupancyThres());
  ml->setClampingThresMin(tree.getClampingThresMin());
  ml->setClampingThresMax(tree.getClampingThresMax());
  if (tree.size() == 0) return ml;
  // OctoMap's binary (.bt) tree stream: two bits per child (unknown, free, occupied, inner).
  std::stringstream stream;
  tree.writeBinaryData(stream);
  ml->readBinaryData(stream);
  ml->updateInnerOccupancy();
  ml->prune();
  return ml;
}

}  // namespace gvio::mapping
