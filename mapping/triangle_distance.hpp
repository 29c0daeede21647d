#pragma once
// Exact point-to-triangle-mesh distance for map-consistency checks against a reference mesh.
//
// Hand-written because the libraries that have it are out of reach: VTK's cell locators (VTK's
// CMake config fails on Debian without MPI, see cmake/GvioDependencies.cmake, so PCL is built
// without it) and CGAL's AABB tree (not a project dependency).
//
// Closest point on a triangle: Ericson, "Real-Time Collision Detection", section 5.1.5 (Voronoi
// regions of vertices, edges and face). Acceleration: a uniform grid hashed into one table. A
// triangle is listed in every cell it may intersect: each cell of its bounding box whose centre
// lies within half a cell diagonal of the triangle (a superset of the cells it crosses). So a
// 40 m road triangle lies in the ~2-3 thousand cells along its face, not in the 40 x 40 x h cells
// of its bounding box, and a small one in a few. A query searches a box growing from half a cell
// by doubling until the best distance found lies inside the searched box (then no unseen
// triangle can be closer: the triangle's closest point lies in a searched cell, which lists it),
// or the search radius is reached.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace gvio::mapping {

// The point of triangle (a, b, c) closest to p. Degenerate triangles (collinear or coincident
// vertices) are handled as their edges.
[[nodiscard]] Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p,
                                                     const Eigen::Vector3d& a,
                                                     const Eigen::Vector3d& b,
                                                     const Eigen::Vector3d& c);

struct MeshClosestPoint {
  double distance_m = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::uint32_t triangle = 0;
};

class TriangleMeshIndex {
 public:
  // Throws InvalidInput when there are no triangles, an index is out of range, a vertex is not
  // finite or the mesh is too large for the grid keys (+-2^20 cells from the origin). 1 m cells:
  // a query for a point near a surface visits 8-27 cells holding a few triangles each.
  TriangleMeshIndex(const std::vector<Eigen::Vector3d>& vertices,
                    const std::vector<std::array<std::uint32_t, 3>>& triangles,
                    double cell_m = 1.0);

  // The closest point of the mesh when it is within max_distance_m of p, else nullopt.
  [[nodiscard]] std::optional<MeshClosestPoint> closest(const Eigen::Vector3d& p,
                                                        double max_distance_m) const;

  [[nodiscard]] std::size_t triangleCount() const { return triangles_.size(); }

 private:
  struct Range {
    std::uint32_t begin = 0, end = 0;
  };
  using Cell = std::array<std::int64_t, 3>;
  [[nodiscard]] static std::uint64_t key(const Cell& cell);
  [[nodiscard]] Cell cellOf(const Eigen::Vector3d& p) const;
  // Updates `best` with the triangles of every cell that meets the box p +- r.
  void searchBox(const Eigen::Vector3d& p, double r, std::optional<MeshClosestPoint>& best) const;

  double cell_m_;
  std::vector<std::array<Eigen::Vector3d, 3>> triangles_;
  Cell lo_{}, hi_{};  // cells holding triangles lie within [lo_, hi_]
  std::unordered_map<std::uint64_t, Range> cells_;
  std::vector<std::uint32_t> cell_triangles_;
};

}  // namespace gvio::mapping
