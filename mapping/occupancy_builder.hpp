#pragma once
// OctoMap occupancy (Hornung et al., Autonomous Robots 2013) of the map: every keyframe's points
// are inserted from the keyframe's camera centre, so the rays clear the free space in front of
// each surface and the end points mark it occupied (computeDiscreteUpdate: one ray per end-point
// voxel, OctoMap's `discretize` insertion; rays end at max_range_m).
//
// The scans go into an OcTree (map.bt: occupied, free and unknown space). The ColorOcTree (map.ot)
// holds the voxels the scans hit, with their mean grey value; at the end each takes the OcTree's
// occupancy there (a voxel hit and later cleared by rays is free in both), so the two trees agree
// on every coloured voxel. The colour tree leaves the free space to the OcTree: on KITTI-00 the
// free space is most of the 18.5 M nodes a full colour tree had (784 MB resident, plus 414 MB
// for its maximum-likelihood OcTree copy), against 9.3 M in the OcTree alone.
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

  // updateInnerOccupancy + prune, the colour tree's occupancy from the OcTree, then hands the
  // trees over (the builder starts afresh).
  struct Trees {
    std::unique_ptr<octomap::OcTree> occupancy;
    std::unique_ptr<octomap::ColorOcTree> color;
  };
  [[nodiscard]] Trees finish();

 private:
  void compact();

  OccupancyConfig config_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::unique_ptr<octomap::ColorOcTree> color_tree_;
  std::size_t nodes_after_compact_ = 0;
};

}  // namespace gvio::mapping
