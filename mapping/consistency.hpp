#pragma once
// Map-consistency metrics against a reference surface (issue 8: median distance of dense points
// <= 0.15 m, of sparse landmarks <= 0.3 m, >= 90 % of occupied voxels within 2 voxels of a true
// surface, two passes agree within 0.5 m median). No I/O: the caller reads the mesh and the map.
#include <cstddef>
#include <vector>

#include <octomap/OcTree.h>

#include "mapping/map_point.hpp"
#include "mapping/triangle_distance.hpp"

namespace gvio::mapping {

// Distances of points to the surface, capped at the search radius: a point with no surface
// within max_distance_m counts as max_distance_m in the statistics and as `far`.
struct SurfaceDistanceStats {
  std::size_t n = 0;
  std::size_t far = 0;
  double max_distance_m = 0.0;
  double median_m = 0.0;  // percentiles interpolate linearly between order statistics (numpy)
  double mean_m = 0.0;
  double p90_m = 0.0;
  double rmse_m = 0.0;
  double within_m = 0.0;         // the threshold of fraction_within
  double fraction_within = 0.0;  // share of points with distance <= within_m
};

[[nodiscard]] SurfaceDistanceStats cloudToSurface(const TriangleMeshIndex& surface,
                                                  const MapCloud& cloud, double max_distance_m,
                                                  double within_m);
[[nodiscard]] SurfaceDistanceStats cloudToSurface(const TriangleMeshIndex& surface,
                                                  const std::vector<Eigen::Vector3d>& points,
                                                  double max_distance_m, double within_m);

// Occupied voxels of the tree (pruned leaves counted as the finest voxels they cover) whose centre
// lies within within_voxels x resolution of the surface.
struct OccupancySurfaceStats {
  std::size_t occupied_voxels = 0;
  std::size_t near_surface = 0;
  double within_m = 0.0;
  double fraction_near = 0.0;
};

[[nodiscard]] OccupancySurfaceStats occupancyNearSurface(const TriangleMeshIndex& surface,
                                                         const octomap::OcTree& tree,
                                                         double within_voxels);

// Agreement of two passes over the same place: for each pass-2 point, the distance to the nearest
// pass-1 point (pcl::KdTreeFLANN); only pass-2 points with a pass-1 neighbour within
// overlap_radius_m count (the overlap), the rest saw what pass 1 did not.
struct PassAgreement {
  std::size_t n_pass1 = 0;
  std::size_t n_pass2 = 0;
  std::size_t n_overlap = 0;
  double overlap_radius_m = 0.0;
  double overlap_fraction = 0.0;  // n_overlap / n_pass2
  double median_m = 0.0;          // over the overlapping points
  double mean_m = 0.0;
  double p90_m = 0.0;
  double within_m = 0.0;         // the agreement bound asked for (0: none)
  double fraction_within = 0.0;  // of the overlapping points, those within within_m
};

[[nodiscard]] PassAgreement twoPassAgreement(const MapCloud& pass1, const MapCloud& pass2,
                                             double overlap_radius_m, double within_m = 0.0);

// The distances behind twoPassAgreement: for each pass-2 point with a pass-1 point within
// overlap_radius_m, the distance to the nearest one.
[[nodiscard]] std::vector<double> overlapDistances(const MapCloud& pass1, const MapCloud& pass2,
                                                   double overlap_radius_m);

// twoPassAgreement's statistics of given overlap distances (`d` is reordered).
[[nodiscard]] PassAgreement agreementOf(std::vector<double>& d, std::size_t n_pass1,
                                        std::size_t n_pass2, double overlap_radius_m,
                                        double within_m);

// Percentile q in [0, 1] with linear interpolation between order statistics (numpy's default);
// reorders `values`. 0 for an empty vector.
[[nodiscard]] double percentile(std::vector<double>& values, double q);

}  // namespace gvio::mapping
