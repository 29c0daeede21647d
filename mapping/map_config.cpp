#include "mapping/map_config.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

// Dense points are kept per keyframe as millimetre int16 coordinates (keyframe_store.hpp).
constexpr double kMaxDenseRange_m = 32.0;

void require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw InvalidInput("map config: " + field + " must be " + rule);
}

bool positive(double v) {
  return std::isfinite(v) && v > 0.0;
}

}  // namespace

void MapConfig::validate() const {
  require(sparse.min_landmark_observations >= 2, "sparse.min_landmark_observations", ">= 2");
  require(positive(sparse.max_landmark_reprojection_px), "sparse.max_landmark_reprojection_px",
          "> 0");
  require(positive(sparse.max_landmark_range_m), "sparse.max_landmark_range_m", "> 0");

  require(dense.every_n_keyframes >= 1, "dense.every_n_keyframes", ">= 1");
  require(std::isfinite(dense.min_spacing_m) && dense.min_spacing_m >= 0.0, "dense.min_spacing_m",
          ">= 0");
  require(std::isfinite(dense.min_rotation_deg) && dense.min_rotation_deg >= 0.0,
          "dense.min_rotation_deg", ">= 0");
  const StereoDepthConfig& s = dense.stereo;
  require(positive(s.downscale) && s.downscale <= 1.0, "dense.stereo.downscale", "in (0, 1]");
  require(s.num_disparities >= 16 && s.num_disparities % 16 == 0, "dense.stereo.num_disparities",
          "a positive multiple of 16");
  require(s.block_size >= 1 && s.block_size % 2 == 1 && s.block_size <= 11,
          "dense.stereo.block_size", "odd, 1..11");
  require(s.uniqueness_ratio >= 0 && s.uniqueness_ratio <= 100, "dense.stereo.uniqueness_ratio",
          "0..100");
  require(s.disp12_max_diff >= -1, "dense.stereo.disp12_max_diff", ">= -1 (-1: no check)");
  require(s.speckle_window_size >= 0, "dense.stereo.speckle_window_size", ">= 0");
  require(s.speckle_range >= 0, "dense.stereo.speckle_range", ">= 0");
  require(s.pre_filter_cap >= 1 && s.pre_filter_cap <= 63, "dense.stereo.pre_filter_cap", "1..63");
  require(positive(s.min_range_m), "dense.stereo.min_range_m", "> 0");
  require(std::isfinite(s.max_range_m) && s.max_range_m > s.min_range_m &&
              s.max_range_m <= kMaxDenseRange_m,
          "dense.stereo.max_range_m", "> min_range_m and <= 32");
  // pcl::VoxelGrid indexes voxels with int32: a keyframe's 64 x 64 x 32 m box needs >= 0.05 m.
  require(std::isfinite(dense.voxel_size_m) && dense.voxel_size_m >= 0.05, "dense.voxel_size_m",
          ">= 0.05");
  require(dense.sor_mean_k >= 1, "dense.sor_mean_k", ">= 1");
  require(positive(dense.sor_stddev_mul), "dense.sor_stddev_mul", "> 0");

  require(positive(occupancy.resolution_m) && occupancy.resolution_m >= 0.01,
          "occupancy.resolution_m", ">= 0.01");
  require(positive(occupancy.max_range_m), "occupancy.max_range_m", "> 0");
}

}  // namespace gvio::mapping
