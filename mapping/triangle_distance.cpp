#include "mapping/triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

constexpr int kKeyBits = 19;  // per axis, signed via an offset
constexpr std::int64_t kKeyOffset = 1LL << (kKeyBits - 1);
constexpr int kMaxLevel = 31;  // 5 bits of level in the key

Eigen::Vector3d closestOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                 const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) * ab;
}

}  // namespace

Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  // A degenerate triangle has no face region (and Ericson's final division is 0/0): its closest
  // point lies on one of its edges.
  if (ab.cross(ac).squaredNorm() <= 1e-24 * ab.squaredNorm() * ac.squaredNorm()) {
    Eigen::Vector3d best = closestOnSegment(p, a, b);
    for (const Eigen::Vector3d& q : {closestOnSegment(p, b, c), closestOnSegment(p, c, a)}) {
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    }
    return best;
  }
  // Ericson 5.1.5: test the Voronoi regions of a, b, edge ab, c, edge ac, edge bc, then the face.
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;

  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;

  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

TriangleMeshIndex::TriangleMeshIndex(const std::vector<Eigen::Vector3d>& vertices,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                     double cell_m)
    : cell_m_(cell_m) {
  if (!std::isfinite(cell_m) || cell_m <= 0.0) throw InvalidInput("mesh index: cell must be > 0 m");
  if (triangles.empty()) throw InvalidInput("mesh index: the mesh has no triangles");
  const double limit = cell_m * static_cast<double>(kKeyOffset - 2);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (!vertices[i].allFinite() || vertices[i].cwiseAbs().maxCoeff() >= limit) {
      throw InvalidInput("mesh index: vertex " + std::to_string(i) +
                         " is not finite or further than " + std::to_string(limit) +
                         " m from the origin");
    }
  }
  // A cube of side c lies inside the ball of radius c sqrt(3) / 2 around its centre: a triangle
  // that meets the cell is at most that far from the centre.
  const double reach = 0.5 * std::sqrt(3.0) * cell_m * (1.0 + 1e-9);
  triangles_.reserve(triangles.size());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> entries;
  entries.reserve(triangles.size() * 4);
  lo_.fill(std::numeric_limits<std::int64_t>::max());
  hi_.fill(std::numeric_limits<std::int64_t>::min());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    std::array<Eigen::Vector3d, 3> tri;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = triangles[t][k];
      if (v >= vertices.size()) {
        throw InvalidInput("mesh index: triangle " + std::to_string(t) +
                           " refers to a missing vertex");
      }
      tri[k] = vertices[v];
    }
    const Cell c0 = cellOf(tri[0].cwiseMin(tri[1]).cwiseMin(tri[2]));
    const Cell c1 = cellOf(tri[0].cwiseMax(tri[1]).cwiseMax(tri[2]));
    for (std::size_t a = 0; a < 3; ++a) {
      lo_[a] = std::min(lo_[a], c0[a]);
      hi_[a] = std::max(hi_[a], c1[a]);
    }
    const bool single = c0 == c1;  // the only candidate cell needs no test
    for (std::int64_t ix = c0[0]; ix <= c1[0]; ++ix) {
      for (std::int64_t iy = c0[1]; iy <= c1[1]; ++iy) {
        for (std::int64_t iz = c0[2]; iz <= c1[2]; ++iz) {
          const Eigen::Vector3d centre =
              cell_m * (Eigen::Vector3d(static_cast<double>(ix), static_cast<double>(iy),
                                        static_cast<double>(iz)) +
                        Eigen::Vector3d::Constant(0.5));
          if (single ||
              (closestPointOnTriangle(centre, tri[0], tri[1], tri[2]) - centre).norm() <= reach) {
            entries.emplace_back(key({ix, iy, iz}), static_cast<std::uint32_t>(t));
          }
        }
      }
    }
    triangles_.push_back(tri);
  }
  // Compressed cell lists: one array of triangle ids sorted by cell, a hash of cell -> range.
  std::sort(entries.begin(), entries.end());
  cell_triangles_.reserve(entries.size());
  for (std::size_t i = 0; i < entries.size();) {
    Range range{static_cast<std::uint32_t>(cell_triangles_.size()), 0};
    const std::uint64_t k = entries[i].first;
    for (; i < entries.size() && entries[i].first == k; ++i) {
      cell_triangles_.push_back(entries[i].second);
    }
    range.end = static_cast<std::uint32_t>(cell_triangles_.size());
    cells_.emplace(k, range);
  }
}

TriangleMeshIndex::Cell TriangleMeshIndex::cellOf(const Eigen::Vector3d& p) const {
  return {static_cast<std::int64_t>(std::floor(p.x() / cell_m_)),
          static_cast<std::int64_t>(std::floor(p.y() / cell_m_)),
          static_cast<std::int64_t>(std::floor(p.z() / cell_m_))};
}

std::uint64_t TriangleMeshIndex::key(const Cell& cell) {
  const auto field = [](std::int64_t i) {
    return static_cast<std::uint64_t>(i + kKeyOffset) & ((1ULL << kKeyBits) - 1);
  };
  return (field(cell[0]) << (2 * kKeyBits)) | (field(cell[1]) << kKeyBits) | field(cell[2]);
}

void TriangleMeshIndex::searchBox(const Eigen::Vector3d& p, double r,
                                  std::optional<MeshClosestPoint>& best) const {
  // Only cells within the mesh's cell range can hold triangles (clamped as doubles, so a huge r
  // cannot overflow the integer cell index).
  Cell lo{}, hi{};
  for (std::size_t a = 0; a < 3; ++a) {
    const auto i = static_cast<Eigen::Index>(a);
    const auto clamped = [&](double x) {
      return static_cast<std::int64_t>(std::clamp(std::floor(x / cell_m_),
                                                  static_cast<double>(lo_[a]) - 1.0,
                                                  static_cast<double>(hi_[a]) + 1.0));
    };
    lo[a] = std::max(clamped(p[i] - r), lo_[a]);
    hi[a] = std::min(clamped(p[i] + r), hi_[a]);
  }
  for (std::int64_t ix = lo[0]; ix <= hi[0]; ++ix) {
    for (std::int64_t iy = lo[1]; iy <= hi[1]; ++iy) {
      for (std::int64_t iz = lo[2]; iz <= hi[2]; ++iz) {
        const auto it = cells_.find(key({ix, iy, iz}));
        if (it == cells_.end()) continue;
        for (std::uint32_t i = it->second.begin; i < it->second.end; ++i) {
          const std::uint32_t t = cell_triangles_[i];
          const auto& tri = triangles_[t];
          const Eigen::Vector3d q = closestPointOnTriangle(p, tri[0], tri[1], tri[2]);
          const double d = (q - p).norm();
          if (!best || d < best->distance_m) best = MeshClosestPoint{d, q, t};
        }
      }
    }
  }
}

std::optional<MeshClosestPoint> TriangleMeshIndex::closest(const Eigen::Vector3d& p,
                                                           double max_distance_m) const {
  if (!p.allFinite() || !(max_distance_m >= 0.0)) return std::nullopt;
  std::optional<MeshClosestPoint> best;
  double r = std::min(0.5 * cell_m_, max_distance_m);
  while (true) {
    searchBox(p, r, best);
    // Every triangle within r of p is listed in a searched cell: the best is final once inside.
    if ((best && best->distance_m <= r) || r >= max_distance_m) break;
    r = std::min(2.0 * r, max_distance_m);
    // Only triangles closer than the best so far matter.
    if (best) r = std::min(r, best->distance_m);
  }
  if (!best || best->distance_m > max_distance_m) return std::nullopt;
  return best;
}

}  // namespace gvio::mapping
