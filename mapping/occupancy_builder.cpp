#include "mapping/occupancy_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace gvio::mapping {
namespace {

// Below this many nodes (~3 MB) a tree is not worth a full update-and-prune pass.
constexpr std::size_t kMinCompactNodes = 200'000;

}  // namespace

OccupancyBuilder::OccupancyBuilder(const OccupancyConfig& config)
    : config_(config),
      tree_(std::make_unique<octomap::OcTree>(config.resolution_m)),
      color_tree_(std::make_unique<octomap::ColorOcTree>(config.resolution_m)) {}

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
  tree_->computeDiscreteUpdate(scan, origin, free_cells, occupied_cells, config_.max_range_m);
  for (const auto& key : free_cells) tree_->updateNode(key, false, true);
  for (const auto& key : occupied_cells) tree_->updateNode(key, true, true);

  // Mean grey value of the scan's points in each occupied voxel, merged into the voxel's colour
  // in the colour tree (which holds the hit voxels only; finish() gives them the OcTree's
  // occupancy).
  struct Sum {
    double intensity = 0.0;
    int n = 0;
  };
  std::unordered_map<octomap::OcTreeKey, Sum, octomap::OcTreeKey::KeyHash> sums;
  for (const auto& p : points_map) {
    octomap::OcTreeKey key;
    if (!tree_->coordToKeyChecked(octomap::point3d(p.x, p.y, p.z), key)) continue;
    if (occupied_cells.count(key) == 0) continue;  // beyond the max range
    Sum& s = sums[key];
    s.intensity += static_cast<double>(p.intensity);
    ++s.n;
  }
  for (const auto& [key, s] : sums) {
    const double grey = std::clamp(std::round(s.intensity / s.n), 0.0, 255.0);
    const auto g = static_cast<std::uint8_t>(grey);
    color_tree_->updateNode(key, true, true);
    color_tree_->averageNodeColor(key, g, g, g);
  }

  if (tree_->size() >= std::max(kMinCompactNodes, nodes_after_compact_ * 3 / 2)) compact();
}

void OccupancyBuilder::compact() {
  tree_->updateInnerOccupancy();
  tree_->prune();
  nodes_after_compact_ = tree_->size();
}

OccupancyBuilder::Trees OccupancyBuilder::finish() {
  compact();
  // Each coloured (hit) voxel takes the OcTree's final occupancy there: a voxel hit once and
  // cleared by later rays is free in both trees.
  std::vector<std::pair<octomap::OcTreeKey, float>> log_odds;
  log_odds.reserve(color_tree_->getNumLeafNodes());
  for (auto it = color_tree_->begin_leafs(); it != color_tree_->end_leafs(); ++it) {
    const octomap::OcTreeNode* node = tree_->search(it.getKey());
    log_odds.emplace_back(it.getKey(),
                          node != nullptr ? node->getLogOdds() : tree_->getClampingThresMinLog());
  }
  for (const auto& [key, value] : log_odds) color_tree_->setNodeValue(key, value, true);
  // ColorOcTree::updateInnerOccupancy (OctoMap 1.9) walks from the root without checking it: a
  // map whose every point lies beyond max_range_m (far landmarks only) has none.
  if (color_tree_->getRoot() != nullptr) {
    color_tree_->updateInnerOccupancy();
    color_tree_->prune();
  }
  Trees trees;
  trees.occupancy = std::move(tree_);
  trees.color = std::move(color_tree_);
  tree_ = std::make_unique<octomap::OcTree>(config_.resolution_m);
  color_tree_ = std::make_unique<octomap::ColorOcTree>(config_.resolution_m);
  nodes_after_compact_ = 0;
  return trees;
}

}  // namespace gvio::mapping
