#include "mapping/point_lod.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>
#include <utility>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

// The cube around every point: the bounding box's largest side, centred, a little larger so that
// the points on its upper faces fall inside the last grid cell, not outside it.
Eigen::AlignedBox3d enclosingCube(const Eigen::AlignedBox3d& box) {
  const double side = std::max(box.sizes().maxCoeff(), 1e-3) * (1.0 + 1e-9);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(side / 2.0);
  return {box.center() - half, box.center() + half};
}

int octantOf(const Eigen::Vector3d& p, const Eigen::Vector3d& centre) {
  return (p.x() >= centre.x() ? 1 : 0) | (p.y() >= centre.y() ? 2 : 0) |
         (p.z() >= centre.z() ? 4 : 0);
}

class Builder {
 public:
  Builder(std::span<const Eigen::Vector3d> p, const PointLodConfig& c) : p_(p), c_(c) {}

  // Places `ids` (increasing) in a new node of `cube` and its descendants; returns its index.
  int place(std::string name, int depth, const Eigen::AlignedBox3d& cube,
            std::vector<std::uint32_t> ids) {
    const int index = static_cast<int>(tree_.nodes.size());
    tree_.nodes.emplace_back();
    PointLodNode node;
    node.name = std::move(name);
    node.depth = depth;
    node.cube = cube;
    for (const std::uint32_t i : ids) node.bounds.extend(p_[i]);
    std::array<std::vector<std::uint32_t>, 8> rest;
    if (ids.size() <= c_.max_points_per_node || depth >= c_.max_depth) {
      node.points = std::move(ids);
    } else {
      sample(cube, ids, node, rest);
    }
    for (int o = 0; o < 8; ++o) {
      if (rest[o].empty()) continue;
      node.children[o] = place(node.name + static_cast<char>('0' + o), depth + 1, octant(cube, o),
                               std::move(rest[o]));
    }
    tree_.nodes[index] = std::move(node);
    return index;
  }

  PointLodTree take() { return std::move(tree_); }

 private:
  // The first point of each grid cell stays; every other goes to its octant's list.
  void sample(const Eigen::AlignedBox3d& cube, const std::vector<std::uint32_t>& ids,
              PointLodNode& node, std::array<std::vector<std::uint32_t>, 8>& rest) const {
    const auto g = static_cast<std::uint64_t>(c_.grid_cells);
    node.spacing_m = cube.sizes().x() / static_cast<double>(g);
    const Eigen::Vector3d centre = cube.center();
    std::unordered_set<std::uint64_t> taken;
    taken.reserve(std::min<std::size_t>(ids.size(), g * g * g));
    for (const std::uint32_t i : ids) {
      const Eigen::Vector3d cell = (p_[i] - cube.min()) / node.spacing_m;
      const auto clamp = [g](double v) {
        return static_cast<std::uint64_t>(std::clamp(v, 0.0, static_cast<double>(g - 1)));
      };
      const std::uint64_t key = (clamp(cell.z()) * g + clamp(cell.y())) * g + clamp(cell.x());
      if (taken.insert(key).second) {
        node.points.push_back(i);
      } else {
        rest[octantOf(p_[i], centre)].push_back(i);
      }
    }
  }

  std::span<const Eigen::Vector3d> p_;
  const PointLodConfig& c_;
  PointLodTree tree_;
};

}  // namespace

void PointLodConfig::validate() const {
  if (grid_cells < 2 || grid_cells > 1024) throw InvalidInput("point LOD: grid_cells in [2, 1024]");
  if (max_points_per_node < 1) throw InvalidInput("point LOD: max_points_per_node must be >= 1");
  if (max_depth < 0 || max_depth > 30) throw InvalidInput("point LOD: max_depth in [0, 30]");
}

Eigen::AlignedBox3d octant(const Eigen::AlignedBox3d& cube, int i) {
  const Eigen::Vector3d c = cube.center();
  Eigen::Vector3d lo = cube.min(), hi = c;
  for (int a = 0; a < 3; ++a) {
    if ((i >> a) & 1) {
      lo[a] = c[a];
      hi[a] = cube.max()[a];
    }
  }
  return {lo, hi};
}

PointLodTree buildPointLod(std::span<const Eigen::Vector3d> p, const PointLodConfig& config) {
  config.validate();
  if (p.size() >= std::numeric_limits<std::uint32_t>::max()) {
    throw InvalidInput("point LOD: more than 2^32 - 1 points");
  }
  std::vector<std::uint32_t> ids;
  ids.reserve(p.size());
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p[i].allFinite()) continue;
    ids.push_back(static_cast<std::uint32_t>(i));
    box.extend(p[i]);
  }
  Builder builder(p, config);
  const std::size_t placed = ids.size();
  if (!ids.empty()) builder.place("r", 0, enclosingCube(box), std::move(ids));
  PointLodTree tree = builder.take();
  tree.points = placed;
  return tree;
}

}  // namespace gvio::mapping
