// Map-consistency metrics: the indexed point-to-mesh distance against a brute force written
// differently (plane projection + inside test, else the three edges), surface statistics on a
// known offset, the occupied-voxel fraction on a hand-made tree, and two-pass agreement.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mapping/consistency.hpp"
#include "mapping/triangle_distance.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

using Vec = Eigen::Vector3d;
using Tri = std::array<std::uint32_t, 3>;

double segmentDistance(const Vec& p, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double t =
      ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Independent reference: if p's projection onto the plane is inside the triangle (same side of
// all three edges), the distance is the plane distance; otherwise the closest point is on an edge.
double bruteTriangleDistance(const Vec& p, const Vec& a, const Vec& b, const Vec& c) {
  const Vec n = (b - a).cross(c - a);
  if (n.norm() > 1e-12) {
    const Vec u = n.normalized();
    const Vec q = p - u.dot(p - a) * u;
    const bool inside = (b - a).cross(q - a).dot(n) >= 0.0 && (c - b).cross(q - b).dot(n) >= 0.0 &&
                        (a - c).cross(q - c).dot(n) >= 0.0;
    if (inside) return (p - q).norm();
  }
  return std::min({segmentDistance(p, a, b), segmentDistance(p, b, c), segmentDistance(p, c, a)});
}

struct Mesh {
  std::vector<Vec> vertices;
  std::vector<Tri> triangles;
  void add(const Vec& a, const Vec& b, const Vec& c) {
    const auto i = static_cast<std::uint32_t>(vertices.size());
    vertices.insert(vertices.end(), {a, b, c});
    triangles.push_back({i, i + 1, i + 2});
  }
};

double bruteDistance(const Mesh& mesh, const Vec& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    best = std::min(best, bruteTriangleDistance(p, mesh.vertices[t[0]], mesh.vertices[t[1]],
                                                mesh.vertices[t[2]]));
  }
  return best;
}

// Random triangles in a 100 m box: small (0.05-1 m), medium (1-5 m), big road-like (20-60 m),
// slivers and a degenerate one.
Mesh randomMesh(std::mt19937& rng) {
  std::uniform_real_distribution<double> pos(-50.0, 50.0), unit(-1.0, 1.0);
  Mesh mesh;
  const auto around = [&](const Vec& centre, double size) -> Vec {
    const double x = unit(rng), y = unit(rng), z = unit(rng);  // in a fixed order
    return centre + size * Vec(x, y, z);
  };
  for (int i = 0; i < 400; ++i) {
    const double cx = pos(rng), cy = pos(rng), cz = 0.2 * pos(rng);
    const Vec centre(cx, cy, cz);
    const double size =
        i % 10 == 0 ? 20.0 + 40.0 * std::abs(unit(rng))
                    : (i % 3 == 0 ? 1.0 + 4.0 * std::abs(unit(rng)) : 0.05 + std::abs(unit(rng)));
    const Vec a = around(centre, size), b = around(centre, size), c = around(centre, size);
    mesh.add(a, b, c);
  }
  const Vec a(1, 2, 3), b(31, -5, 4);
  mesh.add(a, b, a + 0.5 * (b - a) + Vec(0, 1e-4, 0));  // sliver
  mesh.add(a, b, a + 0.25 * (b - a));                   // degenerate (collinear)
  return mesh;
}

TEST(MappingConsistency, ClosestPointOnTriangleRegions) {
  const Vec a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  EXPECT_LT((closestPointOnTriangle(Vec(0.5, 0.5, 3), a, b, c) - Vec(0.5, 0.5, 0)).norm(), 1e-15);
  EXPECT_LT((closestPointOnTriangle(Vec(-1, -1, 1), a, b, c) - a).norm(), 1e-15);   // vertex a
  EXPECT_LT((closestPointOnTriangle(Vec(3, -0.5, 0), a, b, c) - b).norm(), 1e-15);  // vertex b
  EXPECT_LT((closestPointOnTriangle(Vec(1, -1, 0), a, b, c) - Vec(1, 0, 0)).norm(), 1e-15);
  EXPECT_LT((closestPointOnTriangle(Vec(2, 2, 1), a, b, c) - Vec(1, 1, 0)).norm(), 1e-15);
  // Degenerate: collinear vertices behave as the segment.
  EXPECT_NEAR((closestPointOnTriangle(Vec(1, 1, 0), a, b, Vec(1, 0, 0)) - Vec(1, 0, 0)).norm(), 0.0,
              1e-15);
}

TEST(MappingConsistency, IndexedDistanceMatchesBruteForce) {
  std::mt19937 rng(42);
  const Mesh mesh = randomMesh(rng);
  const TriangleMeshIndex index(mesh.vertices, mesh.triangles, 1.0);
  EXPECT_EQ(index.triangleCount(), mesh.triangles.size());

  std::uniform_real_distribution<double> pos(-55.0, 55.0), unit(-1.0, 1.0), small(0.0, 0.3);
  std::vector<Vec> queries;
  for (int i = 0; i < 1500; ++i) {
    const double x = pos(rng), y = pos(rng), z = 0.2 * pos(rng);
    queries.emplace_back(x, y, z);
  }
  // Near vertices and edges, where the Voronoi regions of Ericson's test meet.
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 2) {
    const Vec& a = mesh.vertices[mesh.triangles[t][0]];
    const Vec& b = mesh.vertices[mesh.triangles[t][1]];
    const double rx = unit(rng), ry = unit(rng), rz = unit(rng);
    const Vec r(rx, ry, rz);
    queries.push_back(a + small(rng) * r.normalized());
    queries.push_back(0.5 * (a + b) + small(rng) * r.normalized());
    queries.push_back(a);  // exactly on a vertex
  }
  int checked = 0, within = 0;
  for (const Vec& p : queries) {
    const double expected = bruteDistance(mesh, p);
    const auto found = index.closest(p, 1e6);
    ASSERT_TRUE(found.has_value());
    ASSERT_NEAR(found->distance_m, expected, 1e-9) << p.transpose();
    // The returned point is on the returned triangle and at the returned distance.
    const auto& t = mesh.triangles[found->triangle];
    EXPECT_NEAR(
        bruteTriangleDistance(p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]),
        expected, 1e-9);
    EXPECT_NEAR((found->point - p).norm(), expected, 1e-9);
    // With a capped search: found iff within the cap.
    const auto capped = index.closest(p, 0.7);
    EXPECT_EQ(capped.has_value(), expected <= 0.7);
    if (capped) {
      EXPECT_NEAR(capped->distance_m, expected, 1e-9);
      ++within;
    }
    ++checked;
  }
  EXPECT_GT(within, 300);
  EXPECT_GT(checked - within, 300);
}

TEST(MappingConsistency, RejectsBadMeshes) {
  const std::vector<Vec> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_THROW(TriangleMeshIndex(v, {}), InvalidInput);
  EXPECT_THROW(TriangleMeshIndex(v, {{0, 1, 3}}), InvalidInput);
  EXPECT_THROW(TriangleMeshIndex({{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}}, {{0, 1, 2}}), InvalidInput);
}

// Two triangles covering the plane z = 0 over [-50, 50]^2: big triangles, like a road.
Mesh plane() {
  Mesh mesh;
  mesh.vertices = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TEST(MappingConsistency, SurfaceStatsOfAnOffsetCloud) {
  const Mesh mesh = plane();
  const TriangleMeshIndex index(mesh.vertices, mesh.triangles);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(-40.0, 40.0);
  MapCloud cloud;
  for (int i = 0; i < 2000; ++i) {
    const float z = i % 2 == 0 ? 0.1f : -0.1f;
    cloud.push_back(makeMapPoint(static_cast<float>(xy(rng)), static_cast<float>(xy(rng)), z, 0, 0,
                                 MapPointSource::kDenseStereo));
  }
  SurfaceDistanceStats s = cloudToSurface(index, cloud, 1.0, 0.15);
  EXPECT_EQ(s.n, 2000u);
  EXPECT_EQ(s.far, 0u);
  EXPECT_NEAR(s.median_m, 0.1, 1e-6);
  EXPECT_NEAR(s.mean_m, 0.1, 1e-6);
  EXPECT_NEAR(s.p90_m, 0.1, 1e-6);
  EXPECT_NEAR(s.rmse_m, 0.1, 1e-6);
  EXPECT_DOUBLE_EQ(s.fraction_within, 1.0);
  EXPECT_DOUBLE_EQ(cloudToSurface(index, cloud, 1.0, 0.05).fraction_within, 0.0);

  // 500 points 5 m above: far, counted at the 1 m cap.
  for (int i = 0; i < 500; ++i) {
    cloud.push_back(makeMapPoint(static_cast<float>(xy(rng)), static_cast<float>(xy(rng)), 5.0f, 0,
                                 0, MapPointSource::kDenseStereo));
  }
  s = cloudToSurface(index, cloud, 1.0, 0.15);
  EXPECT_EQ(s.n, 2500u);
  EXPECT_EQ(s.far, 500u);
  EXPECT_NEAR(s.median_m, 0.1, 1e-6);
  EXPECT_NEAR(s.mean_m, (2000 * 0.1 + 500 * 1.0) / 2500.0, 1e-6);
  EXPECT_NEAR(s.p90_m, 1.0, 1e-9);
  EXPECT_NEAR(s.rmse_m, std::sqrt((2000 * 0.01 + 500 * 1.0) / 2500.0), 1e-6);
  EXPECT_DOUBLE_EQ(s.fraction_within, 0.8);

  // Plain vectors give the same numbers; percentiles interpolate like numpy.
  const std::vector<Vec> pts{{0, 0, 0.1}, {0, 0, 0.2}, {0, 0, 0.3}, {0, 0, 0.4}};
  s = cloudToSurface(index, pts, 1.0, 0.25);
  EXPECT_NEAR(s.median_m, 0.25, 1e-12);
  EXPECT_NEAR(s.p90_m, 0.37, 1e-12);
  EXPECT_DOUBLE_EQ(s.fraction_within, 0.5);
}

TEST(MappingConsistency, OccupiedVoxelsNearTheSurface) {
  const Mesh mesh = plane();
  const TriangleMeshIndex index(mesh.vertices, mesh.triangles);
  octomap::OcTree tree(0.2);
  // 10 voxels on the surface (centres 0.1 m above), 5 floating 1.1 m above it.
  for (int i = 0; i < 10; ++i) tree.updateNode(octomap::point3d(1.1f + 0.2f * i, 3.1f, 0.1f), true);
  for (int i = 0; i < 5; ++i) tree.updateNode(octomap::point3d(-3.1f, 0.1f + 0.2f * i, 1.1f), true);
  // A pruned 2 x 2 x 2 block (one 0.4 m leaf) at 0.1 and 0.3 m: 8 voxels within 0.4 m.
  for (float x : {10.1f, 10.3f}) {
    for (float y : {10.1f, 10.3f}) {
      for (float z : {0.1f, 0.3f}) {
        for (int k = 0; k < 20; ++k) tree.updateNode(octomap::point3d(x, y, z), true);
      }
    }
  }
  // A free voxel does not count.
  tree.updateNode(octomap::point3d(5.1f, 5.1f, 0.1f), false);
  tree.updateInnerOccupancy();
  tree.prune();
  bool has_pruned_leaf = false;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    has_pruned_leaf |= it.getDepth() < tree.getTreeDepth();
  }
  ASSERT_TRUE(has_pruned_leaf);

  const OccupancySurfaceStats s = occupancyNearSurface(index, tree, 2.0);
  EXPECT_EQ(s.occupied_voxels, 23u);
  EXPECT_EQ(s.near_surface, 18u);
  EXPECT_NEAR(s.within_m, 0.4, 1e-12);
  EXPECT_NEAR(s.fraction_near, 18.0 / 23.0, 1e-12);
  // Within 1 voxel (0.2 m) the upper layer of the block (0.3 m) no longer counts.
  EXPECT_EQ(occupancyNearSurface(index, tree, 1.0).near_surface, 14u);
}

TEST(MappingConsistency, TwoPassAgreementOnNoisyPlaneSamplings) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> xy(0.0f, 10.0f), x2(0.0f, 15.0f);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  MapCloud pass1, pass2, pass2_offset;
  for (int i = 0; i < 40000; ++i) {
    const float x = xy(rng), y = xy(rng), z = noise(rng);
    pass1.push_back(makeMapPoint(x, y, z, 0, 0, MapPointSource::kDenseStereo));
  }
  for (int i = 0; i < 9000; ++i) {
    // A third of pass 2 lies beyond pass 1 (x in 10..15): no overlap there.
    const float x = x2(rng), y = xy(rng);
    pass2.push_back(makeMapPoint(x, y, noise(rng), 0, 0, MapPointSource::kDenseStereo));
    pass2_offset.push_back(
        makeMapPoint(x, y, 0.3f + noise(rng), 0, 0, MapPointSource::kDenseStereo));
  }
  PassAgreement same = twoPassAgreement(pass1, pass2, 1.0);
  EXPECT_EQ(same.n_pass1, 40000u);
  EXPECT_EQ(same.n_pass2, 9000u);
  EXPECT_NEAR(same.overlap_fraction, 11.0 / 15.0, 0.02);  // x < 11: within 1 m of pass 1
  EXPECT_LT(same.median_m, 0.06);
  EXPECT_GT(same.median_m, 0.01);

  const PassAgreement shifted = twoPassAgreement(pass1, pass2_offset, 1.0);
  // The nearest pass-1 point is the one whose noise brings it closest: a little under 0.3 m.
  EXPECT_GT(shifted.median_m, 0.26);
  EXPECT_LT(shifted.median_m, 0.32);
  EXPECT_GE(shifted.p90_m, shifted.median_m);
  EXPECT_NEAR(shifted.overlap_fraction, same.overlap_fraction, 0.03);
  // A radius smaller than the offset: no overlap.
  EXPECT_EQ(twoPassAgreement(pass1, pass2_offset, 0.1).n_overlap, 0u);
  EXPECT_EQ(twoPassAgreement(MapCloud(), pass2, 1.0).n_overlap, 0u);
  EXPECT_THROW(std::ignore = twoPassAgreement(pass1, pass2, 0.0), InvalidInput);
  // The share within a bound: all of the aligned pass but the band just past pass 1's edge
  // (x in 10.2..11 of the overlap's 0..11 m: 7 %), none of the 0.3 m offset one.
  EXPECT_NEAR(twoPassAgreement(pass1, pass2, 1.0, 0.2).fraction_within, 1.0 - 0.8 / 11.0, 0.01);
  EXPECT_LT(twoPassAgreement(pass1, pass2_offset, 1.0, 0.2).fraction_within, 0.01);
  EXPECT_EQ(twoPassAgreement(pass1, pass2, 1.0, 0.2).within_m, 0.2);
}

}  // namespace
}  // namespace gvio::mapping
