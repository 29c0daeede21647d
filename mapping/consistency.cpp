#include "mapping/consistency.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <pcl/kdtree/kdtree_flann.h>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

template <class PointAt>
SurfaceDistanceStats distanceStats(const TriangleMeshIndex& surface, std::size_t n,
                                   const PointAt& point_at, double max_distance_m,
                                   double within_m) {
  if (!std::isfinite(max_distance_m) || max_distance_m <= 0.0) {
    throw InvalidInput("surface distance: max distance must be > 0 m");
  }
  SurfaceDistanceStats stats;
  stats.max_distance_m = max_distance_m;
  stats.within_m = within_m;
  std::vector<double> d;
  d.reserve(n);
  std::size_t within = 0;
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto closest = surface.closest(point_at(i), max_distance_m);
    const double di = closest ? closest->distance_m : max_distance_m;
    if (!closest) ++stats.far;
    if (di <= within_m) ++within;
    sum += di;
    sum2 += di * di;
    d.push_back(di);
  }
  stats.n = n;
  if (n == 0) return stats;
  const auto nd = static_cast<double>(n);
  stats.mean_m = sum / nd;
  stats.rmse_m = std::sqrt(sum2 / nd);
  stats.fraction_within = static_cast<double>(within) / nd;
  stats.median_m = percentile(d, 0.5);
  stats.p90_m = percentile(d, 0.9);
  return stats;
}

}  // namespace

double percentile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, values.size() - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
  const double v_lo = values[lo];
  if (hi == lo) return v_lo;
  // The next order statistic is the smallest value above position lo.
  const double v_hi =
      *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(hi), values.end());
  return v_lo + (pos - static_cast<double>(lo)) * (v_hi - v_lo);
}

SurfaceDistanceStats cloudToSurface(const TriangleMeshIndex& surface, const MapCloud& cloud,
                                    double max_distance_m, double within_m) {
  return distanceStats(
      surface, cloud.size(),
      [&cloud](std::size_t i) { return cloud[i].getVector3fMap().cast<double>().eval(); },
      max_distance_m, within_m);
}

SurfaceDistanceStats cloudToSurface(const TriangleMeshIndex& surface,
                                    const std::vector<Eigen::Vector3d>& points,
                                    double max_distance_m, double within_m) {
  return distanceStats(
      surface, points.size(), [&points](std::size_t i) { return points[i]; }, max_distance_m,
      within_m);
}

OccupancySurfaceStats occupancyNearSurface(const TriangleMeshIndex& surface,
                                           const octomap::OcTree& tree, double within_voxels) {
  OccupancySurfaceStats stats;
  const double res = tree.getResolution();
  stats.within_m = within_voxels * res;
  const unsigned max_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    // A pruned leaf of size s stands for (s / res)^3 finest voxels: test each centre.
    const int per_axis = 1 << (max_depth - it.getDepth());
    const double size = it.getSize();
    const Eigen::Vector3d corner(it.getX() - size / 2.0, it.getY() - size / 2.0,
                                 it.getZ() - size / 2.0);
    for (int i = 0; i < per_axis; ++i) {
      for (int j = 0; j < per_axis; ++j) {
        for (int k = 0; k < per_axis; ++k) {
          const Eigen::Vector3d centre = corner + res * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
          ++stats.occupied_voxels;
          if (surface.closest(centre, stats.within_m)) ++stats.near_surface;
        }
      }
    }
  }
  if (stats.occupied_voxels > 0) {
    stats.fraction_near =
        static_cast<double>(stats.near_surface) / static_cast<double>(stats.occupied_voxels);
  }
  return stats;
}

std::vector<double> overlapDistances(const MapCloud& pass1, const MapCloud& pass2,
                                     double overlap_radius_m) {
  if (!std::isfinite(overlap_radius_m) || overlap_radius_m <= 0.0) {
    throw InvalidInput("two-pass agreement: overlap radius must be > 0 m");
  }
  std::vector<double> d;
  if (pass1.empty() || pass2.empty()) return d;
  // KdTreeFLANN is precompiled for PCL's own point types: index plain xyz copies.
  auto reference = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  reference->reserve(pass1.size());
  for (const auto& p : pass1) reference->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(reference);
  pcl::Indices index(1);
  std::vector<float> dist2(1);
  const double r2 = overlap_radius_m * overlap_radius_m;
  for (const auto& p : pass2) {
    if (tree.nearestKSearch(pcl::PointXYZ(p.x, p.y, p.z), 1, index, dist2) < 1) continue;
    if (static_cast<double>(dist2[0]) <= r2) d.push_back(std::sqrt(static_cast<double>(dist2[0])));
  }
  return d;
}

PassAgreement agreementOf(std::vector<double>& d, std::size_t n_pass1, std::size_t n_pass2,
                          double overlap_radius_m, double within_m) {
  PassAgreement result;
  result.n_pass1 = n_pass1;
  result.n_pass2 = n_pass2;
  result.overlap_radius_m = overlap_radius_m;
  result.within_m = within_m;
  result.n_overlap = d.size();
  if (d.empty() || n_pass2 == 0) return result;
  result.overlap_fraction = static_cast<double>(d.size()) / static_cast<double>(n_pass2);
  result.mean_m = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
  result.fraction_within = static_cast<double>(std::count_if(
                               d.begin(), d.end(), [&](double v) { return v <= within_m; })) /
                           static_cast<double>(d.size());
  result.median_m = percentile(d, 0.5);
  result.p90_m = percentile(d, 0.9);
  return result;
}

PassAgreement twoPassAgreement(const MapCloud& pass1, const MapCloud& pass2,
                               double overlap_radius_m, double within_m) {
  std::vector<double> d = overlapDistances(pass1, pass2, overlap_radius_m);
  return agreementOf(d, pass1.size(), pass2.size(), overlap_radius_m, within_m);
}

}  // namespace gvio::mapping
