#include "mapping/point_lod.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "odometry/error.hpp"
#include "odometry/parallel_for.hpp"

namespace gvio::mapping {
namespace {

// The cube around every point: the bounding box's largest side, centred, a little larger so that
// the points on its upper faces fall inside the last grid cell, not outside it.
Eigen::AlignedBox3d enclosingCube(const Eigen::AlignedBox3d& box) {
  const double side = std::max(box.sizes().maxCoeff(), 1e-3) * (1.0 + 1e-9);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(side / 2.0);
  return {box.center() - half, box.center() + half};
}

// Every point's position in the root cube as integers of kBits bits per axis: a node of depth d
// has its octant in bit kBits - 1 - d and its grid cell (of 2^k per axis) in the k bits below, so
// each level costs shifts instead of floating-point divisions (2 M points: 4x faster).
constexpr int kBits = 30;

// The integer positions, shared (read-only) by the builders of the root's subtrees.
struct Quantised {
  Quantised(std::span<const Eigen::Vector3d> p, const Eigen::AlignedBox3d& root) : q(p.size()) {
    const double scale = std::ldexp(1.0, kBits) / root.sizes().x();
    const double top = std::ldexp(1.0, kBits) - 1.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!p[i].allFinite()) continue;
      const Eigen::Vector3d v = ((p[i] - root.min()) * scale).cwiseMax(0.0).cwiseMin(top);
      q[i] = {static_cast<std::uint32_t>(v.x()), static_cast<std::uint32_t>(v.y()),
              static_cast<std::uint32_t>(v.z())};
    }
  }
  std::vector<std::array<std::uint32_t, 3>> q;
};

class Builder {
 public:
  Builder(std::span<const Eigen::Vector3d> p, const PointLodConfig& c, const Quantised& q)
      : p_(p), c_(c), grid_bits_(std::countr_zero(static_cast<unsigned>(c.grid_cells))), q_(q.q) {}

  // Whether a node of `ids` at `depth` keeps them all (a leaf).
  [[nodiscard]] bool keepsAll(std::size_t ids, int depth) const {
    return ids <= c_.max_points_per_node || depth >= c_.max_depth;
  }

  // A node of `cube` for `ids` (increasing): all of them for a leaf, else its grid sample, the
  // rest going to `rest` by octant; its bounds are its own points' (the caller adds its
  // children's).
  PointLodNode node(std::string name, int depth, const Eigen::AlignedBox3d& cube,
                    std::vector<std::uint32_t> ids,
                    std::array<std::vector<std::uint32_t>, 8>& rest) {
    PointLodNode node;
    node.name = std::move(name);
    node.depth = depth;
    node.cube = cube;
    if (keepsAll(ids.size(), depth)) {
      node.points = std::move(ids);
    } else {
      sample(depth, ids, node, rest);
      node.spacing_m = cube.sizes().x() / static_cast<double>(c_.grid_cells);
    }
    for (const std::uint32_t i : node.points) node.bounds.extend(p_[i]);
    return node;
  }

  // Places `ids` (increasing) in a new node of `cube` and its descendants; returns its index.
  int place(std::string name, int depth, const Eigen::AlignedBox3d& cube,
            std::vector<std::uint32_t> ids) {
    const int index = static_cast<int>(tree_.nodes.size());
    tree_.nodes.emplace_back();
    std::array<std::vector<std::uint32_t>, 8> rest;
    PointLodNode node = this->node(std::move(name), depth, cube, std::move(ids), rest);
    for (int o = 0; o < 8; ++o) {
      if (rest[o].empty()) continue;
      node.children[o] = place(node.name + static_cast<char>('0' + o), depth + 1, octant(cube, o),
                               std::move(rest[o]));
      node.bounds.extend(tree_.nodes[static_cast<std::size_t>(node.children[o])].bounds);
    }
    tree_.nodes[static_cast<std::size_t>(index)] = std::move(node);
    return index;
  }

  PointLodTree take() { return std::move(tree_); }

 private:
  // The first point of each grid cell stays; every other goes to its octant's list.
  void sample(int depth, const std::vector<std::uint32_t>& ids, PointLodNode& node,
              std::array<std::vector<std::uint32_t>, 8>& rest) {
    const int k = grid_bits_;
    const int cell_shift = kBits - depth - k;  // >= 0: validate() bounds max_depth + k
    const int octant_shift = kBits - depth - 1;
    const std::uint32_t mask = (1u << k) - 1u;
    // One bit per grid cell (64^3 cells: 32 KB), reused from node to node.
    taken_.assign(((std::size_t{1} << (3 * k)) + 63) / 64, 0);
    for (const std::uint32_t i : ids) {
      const std::array<std::uint32_t, 3>& q = q_[i];
      const std::uint64_t key = (std::uint64_t{(q[2] >> cell_shift) & mask} << (2 * k)) |
                                (std::uint64_t{(q[1] >> cell_shift) & mask} << k) |
                                ((q[0] >> cell_shift) & mask);
      std::uint64_t& word = taken_[key / 64];
      const std::uint64_t bit = std::uint64_t{1} << (key % 64);
      if ((word & bit) == 0) {
        word |= bit;
        node.points.push_back(i);
      } else {
        const int o =
            static_cast<int>(((q[0] >> octant_shift) & 1u) | (((q[1] >> octant_shift) & 1u) << 1) |
                             (((q[2] >> octant_shift) & 1u) << 2));
        rest[o].push_back(i);
      }
    }
  }

  std::span<const Eigen::Vector3d> p_;
  const PointLodConfig& c_;
  int grid_bits_;
  const std::vector<std::array<std::uint32_t, 3>>& q_;  // integer positions in the root cube
  std::vector<std::uint64_t> taken_;                    // the sampled node's taken grid cells
  PointLodTree tree_;
};

// The root sampled here, its eight subtrees built on `config.threads` threads, then laid out in
// the order one thread would have made them (the root, then each octant's subtree depth first):
// the same tree whatever the number of threads.
void buildInParallel(std::span<const Eigen::Vector3d> p, const PointLodConfig& config,
                     const Quantised& q, const Eigen::AlignedBox3d& root,
                     std::vector<std::uint32_t> ids, PointLodTree& out) {
  std::array<std::vector<std::uint32_t>, 8> rest;
  PointLodNode node = Builder(p, config, q).node("r", 0, root, std::move(ids), rest);
  std::array<PointLodTree, 8> sub;
  parallelFor(8, threadCount(config.threads, 8), [&](std::size_t o) {
    if (rest[o].empty()) return;
    Builder b(p, config, q);
    b.place(std::string("r") + static_cast<char>('0' + o), 1, octant(root, static_cast<int>(o)),
            std::move(rest[o]));
    sub[o] = b.take();
  });
  out.nodes.push_back(std::move(node));
  for (int o = 0; o < 8; ++o) {
    if (sub[o].nodes.empty()) continue;
    const int offset = static_cast<int>(out.nodes.size());
    for (PointLodNode& n : sub[o].nodes) {
      for (int& c : n.children) {
        if (c >= 0) c += offset;
      }
      out.nodes.push_back(std::move(n));
    }
    out.nodes.front().children[o] = offset;
    out.nodes.front().bounds.extend(out.nodes[static_cast<std::size_t>(offset)].bounds);
  }
}

}  // namespace

void PointLodConfig::validate() const {
  if (grid_cells < 2 || grid_cells > 1024 ||
      !std::has_single_bit(static_cast<unsigned>(grid_cells))) {
    throw InvalidInput("point LOD: grid_cells must be a power of two in [2, 1024]");
  }
  if (max_points_per_node < 1) throw InvalidInput("point LOD: max_points_per_node must be >= 1");
  if (max_depth < 0 || max_depth > 20) throw InvalidInput("point LOD: max_depth in [0, 20]");
  if (threads < 0 || threads > 64) throw InvalidInput("point LOD: threads in [0, 64]");
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
  const std::size_t placed = ids.size();
  if (ids.empty()) return {};
  const Eigen::AlignedBox3d root = enclosingCube(box);
  const Quantised q(p, root);
  PointLodTree tree;
  Builder top(p, config, q);
  if (top.keepsAll(ids.size(), 0)) {
    top.place("r", 0, root, std::move(ids));
    tree = top.take();
  } else {
    buildInParallel(p, config, q, root, std::move(ids), tree);
  }
  tree.points = placed;
  return tree;
}

}  // namespace gvio::mapping
