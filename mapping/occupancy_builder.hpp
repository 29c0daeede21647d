#pragma once
// OctoMap occupancy (Hornung et al., Autonomous Robots 2013) of the map: every keyframe's points
// are inserted from the keyframe's camera centre, so the rays clear the free space in front of
// each surface and the end points mark it occupied (computeDiscreteUpdate: one ray per end-point
// voxel, OctoMap's `discretize` insertion; rays end at max_range_m).
//
// The scans go into a ColorOcTree (grey intensity; map.ot). The OcTree (map.bt) is made from it
// at the end as its maximum-likelihood copy: OctoMap's own binary stream of the ColorOcTree read
// into an OcTree. Both trees would receive identical log-odds updates, so the occupied / free /
// unknown classification is the same (the test checks it against a directly filled OcTree), and
// a .bt file stores exactly that maximum-likelihood tree anyway. One tree during the drive halves
// the insertion time and the memory: the unpruned free space of a whole drive is the map's
// largest in-memory structure.
#include <Eigen/Core>
#include <cstddef>
#include <memory>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "mapping/map_config.hpp"
#include "mapping/stereo_depth.hpp"

namespace gvio::mapping {

class OccupancyBuilder {
 public:
  explicit OccupancyBuilder(const OccupancyConfig& config);

  // One scan in the map frame (intensity 0..255) seen from origin_map. Inner nodes are updated
  // lazily; whenever the tree has grown by half since the last time, it is updated and pruned
  // (amortised O(1) per new node, memory bounded by the pruned map).
  void insert(const CameraCloud& points_map, const Eigen::Vector3d& origin_map);

  // updateInnerOccupancy + prune, then hands the trees over (the builder starts afresh).
  struct Trees {
    std::unique_ptr<octomap::OcTree> occupancy;
    std::unique_ptr<octomap::ColorOcTree> color;
  };
  [[nodiscard]] Trees finish();

  [[nodiscard]] const octomap::ColorOcTree& colorTree() const { return *color_tree_; }

 private:
  void compact();

  OccupancyConfig config_;
  std::unique_ptr<octomap::ColorOcTree> color_tree_;
  std::size_t nodes_after_compact_ = 0;
};

// The maximum-likelihood occupancy of a tree (free / occupied leaves at the clamping thresholds,
// unknown space left out), updated and pruned.
[[nodiscard]] std::unique_ptr<octomap::OcTree> maximumLikelihoodOcTree(
    const octomap::ColorOcTree& tree);

}  // namespace gvio::mapping
