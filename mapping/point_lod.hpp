#pragma once
// A level-of-detail octree over a point cloud, for streaming it (3D Tiles, the web viewer): each
// node holds a thinned sample of the points in its cube, its children the rest, so a reader that
// stops at any depth sees the whole extent at a coarser spacing, and the union of all nodes is
// every point exactly once ("additive" refinement: 3D Tiles 1.0, sec. "Refinement"; the sampling
// is the grid subsampling of Potree, Schuetz 2016, "Potree: Rendering Large Point Clouds in Web
// Browsers", sec. 3.2, with a fixed grid per node instead of a Poisson-disk test).
//
// A node keeps, in input order, the first point falling into each empty cell of a grid of
// `grid_cells`^3 over its cube; a node with at most `max_points_per_node` points keeps them all
// and has no children. Deterministic: the same points in the same order give the same tree,
// whatever the number of threads.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace gvio::mapping {

struct PointLodConfig {
  int grid_cells = 64;  // per axis, per node (a power of two): a node holds up to 64^3 points
  std::size_t max_points_per_node = 50'000;  // a node with at most this many keeps them all
  int max_depth = 20;     // at most 20; a node this deep keeps everything left (duplicates)
  int threads = 0;        // the root's subtrees built on this many threads (0: one per core);
                          // the tree is the same whatever the number
  void validate() const;  // throws InvalidInput
};

struct PointLodNode {
  std::string name;                   // "r" for the root, then one digit 0-7 per level (octant)
  int depth = 0;                      // 0 at the root
  Eigen::AlignedBox3d cube;           // the node's cube (its children split it in 8)
  Eigen::AlignedBox3d bounds;         // the bounds of the points of the node and its descendants
  std::vector<std::uint32_t> points;  // indices into the input, increasing
  double spacing_m = 0.0;             // the node's grid cell size; 0 for a node that kept all
  std::array<int, 8> children{-1, -1, -1, -1, -1, -1, -1, -1};  // node indices, -1 for none
};

struct PointLodTree {
  std::vector<PointLodNode> nodes;  // nodes[0] is the root (absent for an empty cloud)
  std::size_t points = 0;           // the number of input points placed (the finite ones)
};

// Octant i of `cube`: bit 0 x, bit 1 y, bit 2 z (set: the upper half).
Eigen::AlignedBox3d octant(const Eigen::AlignedBox3d& cube, int i);

// Builds the tree over the finite points of `p` (non-finite ones are left out). Throws
// InvalidInput for more than 2^32 - 1 points.
PointLodTree buildPointLod(std::span<const Eigen::Vector3d> p, const PointLodConfig& config);

}  // namespace gvio::mapping
