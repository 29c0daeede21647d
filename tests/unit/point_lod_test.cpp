// mapping::buildPointLod: every point in exactly one node, inside its node's cube, each node's
// sample one point per grid cell, deterministic.
#include "mapping/point_lod.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

std::vector<Eigen::Vector3d> street(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> along(0.0, 400.0), across(-12.0, 12.0), up(0.0, 8.0);
  std::vector<Eigen::Vector3d> p(n);
  for (auto& x : p) x = {along(rng), across(rng), up(rng)};
  return p;
}

TEST(PointLod, EveryPointOnceInsideItsCube) {
  std::vector<Eigen::Vector3d> p = street(200'000, 1);
  p[17] = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  PointLodConfig c;
  c.grid_cells = 16;
  c.max_points_per_node = 5'000;
  const PointLodTree tree = buildPointLod(p, c);
  EXPECT_EQ(tree.points, p.size() - 1);
  std::vector<int> seen(p.size(), 0);
  std::size_t placed = 0;
  for (const PointLodNode& node : tree.nodes) {
    EXPECT_EQ(static_cast<int>(node.name.size()) - 1, node.depth);
    EXPECT_TRUE(std::is_sorted(node.points.begin(), node.points.end()));
    std::set<std::tuple<int, int, int>> cells;
    for (const std::uint32_t i : node.points) {
      ++seen[i];
      ++placed;
      EXPECT_TRUE(node.cube.contains(p[i])) << node.name;
      EXPECT_TRUE(node.bounds.contains(p[i])) << node.name;
      if (node.spacing_m > 0.0) {  // a sampled node: one point per grid cell
        const Eigen::Vector3d g = (p[i] - node.cube.min()) / node.spacing_m;
        EXPECT_TRUE(cells.emplace(int(g.x()), int(g.y()), int(g.z())).second) << node.name;
      }
    }
    if (node.spacing_m > 0.0) {
      EXPECT_LE(node.points.size(), 16u * 16u * 16u);
    }
    for (int o = 0; o < 8; ++o) {
      if (node.children[o] < 0) continue;
      const PointLodNode& child = tree.nodes[static_cast<std::size_t>(node.children[o])];
      EXPECT_EQ(child.name, node.name + char('0' + o));
      EXPECT_TRUE(node.cube.contains(child.cube));
      EXPECT_TRUE(node.bounds.contains(child.bounds));
      EXPECT_GT(node.spacing_m, 0.0);  // only a sampled node has children
    }
  }
  EXPECT_EQ(placed, p.size() - 1);
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(seen[i], i == 17 ? 0 : 1) << i;
  EXPECT_GT(tree.nodes.size(), 8u);
  // The root alone shows the whole street at the root's spacing.
  EXPECT_NEAR(tree.nodes[0].bounds.sizes().x(), 400.0, 1.0);
}

// The same tree on one thread and on many (the root's subtrees are built in parallel), its nodes
// depth first (their names in lexicographic order).
TEST(PointLod, DeterministicWhateverTheThreads) {
  const std::vector<Eigen::Vector3d> p = street(50'000, 2);
  PointLodConfig c;
  c.max_points_per_node = 2'000;
  c.grid_cells = 8;
  c.threads = 1;
  const PointLodTree a = buildPointLod(p, c);
  EXPECT_TRUE(std::is_sorted(a.nodes.begin(), a.nodes.end(),
                             [](const auto& x, const auto& y) { return x.name < y.name; }));
  for (const int threads : {1, 3, 8, 0}) {
    c.threads = threads;
    const PointLodTree b = buildPointLod(p, c);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (std::size_t k = 0; k < a.nodes.size(); ++k) {
      EXPECT_EQ(a.nodes[k].name, b.nodes[k].name);
      EXPECT_EQ(a.nodes[k].points, b.nodes[k].points);
      EXPECT_EQ(a.nodes[k].children, b.nodes[k].children);
      EXPECT_TRUE(a.nodes[k].bounds.isApprox(b.nodes[k].bounds, 0.0));
      EXPECT_EQ(a.nodes[k].spacing_m, b.nodes[k].spacing_m);
    }
  }
}

TEST(PointLod, SmallCloudIsOneNodeAndCoincidentPointsStop) {
  const std::vector<Eigen::Vector3d> few = street(100, 3);
  const PointLodTree one = buildPointLod(few, {});
  ASSERT_EQ(one.nodes.size(), 1u);
  EXPECT_EQ(one.nodes[0].points.size(), 100u);
  EXPECT_EQ(one.nodes[0].spacing_m, 0.0);
  // 3000 copies of one point: split until max_depth, never lost, never looping.
  PointLodConfig c;
  c.max_points_per_node = 10;
  c.max_depth = 6;
  const std::vector<Eigen::Vector3d> same(3000, Eigen::Vector3d(1, 2, 3));
  const PointLodTree deep = buildPointLod(same, c);
  std::size_t placed = 0;
  for (const auto& node : deep.nodes) {
    placed += node.points.size();
    EXPECT_LE(node.depth, 6);
  }
  EXPECT_EQ(placed, 3000u);
  EXPECT_TRUE(buildPointLod(std::vector<Eigen::Vector3d>{}, {}).nodes.empty());
  c.grid_cells = 1;
  EXPECT_THROW(buildPointLod(few, c), InvalidInput);
}

}  // namespace
}  // namespace gvio::mapping
