#pragma once
// Settings of the map builder: sparse landmark map, dense stereo map, OctoMap occupancy. Plain
// structs with defaults; validate() throws InvalidInput naming the offending field.
namespace gvio::mapping {

struct SparseMapConfig {
  // A landmark triangulated from 4+ views has a baseline long enough that its depth is no longer
  // dominated by one pixel of noise (two-view depth on KITTI at 20 m is good to ~1 m only).
  int min_landmark_observations = 4;
  // The VIO's pixel noise is 1 px (vio.pixel_sigma_px); a mean residual above 1.5 sigma marks a
  // landmark the window fitted badly (occlusion boundary, repeated texture).
  double max_landmark_reprojection_px = 1.5;
  // The VIO keeps landmarks up to vio.max_depth_m (1000 m) for what they say about its rotation,
  // but their stereo depth is poor there (a 0.5 px disparity error at 300 m on KITTI's pair is
  // 100 m): landmarks farther than this from their keyframe are left out of the map.
  double max_landmark_range_m = 80.0;
};

// cv::StereoSGBM (Hirschmueller 2008) on the rectified pair, run at `downscale` x resolution.
struct StereoDepthConfig {
  // Half resolution: SGBM's cost is width x height x disparities, so 0.5 is ~8x cheaper than full
  // size (4x pixels, 2x disparities for the same depth range) and fits the 60 ms keyframe budget.
  double downscale = 0.5;
  // Disparity search range in downscaled pixels (multiple of 16). KITTI at half size has
  // f*b = 359 px * 0.54 m = 194 px m, so 64 disparities reach down to ~3 m: closer than that a
  // KITTI camera (1.65 m above the road, 29 deg vertical field) sees almost nothing but the bonnet.
  int num_disparities = 64;
  // Matching block (odd). 5 at half size = 10 px at full size: large enough for the texture of
  // asphalt and facades, small enough not to fatten depth edges.
  int block_size = 5;
  // Smoothness penalties P1, P2 are OpenCV's recommended 8 and 32 x block_size^2 (per channel).
  // Confidence filters (pixels failing them get no depth):
  int uniqueness_ratio = 15;      // best cost must beat the second best by 15 % (OpenCV: 5-15)
  int disp12_max_diff = 1;        // left-right consistency check, in downscaled pixels
  int speckle_window_size = 100;  // connected blobs smaller than this (px) are noise ...
  int speckle_range = 2;          // ... when their disparity varies by at most this (px)
  int pre_filter_cap = 63;        // OpenCV's default clip of the x-derivative prefilter
  // Range gate on the camera-frame depth (z). Depth error grows as z^2 / (f b) * sigma_d. On the
  // simulated demo drive with true poses (tests/unit/mapping_sim_test.cpp) the dense points' median
  // distance to the true surfaces is 0.017 / 0.031 / 0.056 / 0.080 m for a 10 / 15 / 20 / 25 m
  // gate, and 99.9 / 97 / 93 / 87 % of occupied voxels lie within 2 voxels of a surface: 15 m
  // leaves most of the 0.15 m and 90 % targets to pose errors, covers the road and both facades
  // of a street, and holds half the points a 20 m gate would. 1 m: below the reach of the
  // disparity range anyway (see num_disparities).
  double min_range_m = 1.0;
  double max_range_m = 15.0;
};

struct DenseMapConfig {
  bool enabled = true;        // dense stereo points (needs a stereo rig)
  int every_n_keyframes = 1;  // stereo depth on every n-th keyframe (1: all; raise to save time)
  // ... and only once the camera has moved this far, or turned this much, since the last keyframe
  // with depth (VIO poses). A car at 10 Hz makes nearly every frame a keyframe (~0.8 m apart), and
  // every surface within the 15 m depth gate would be triangulated ~20 times over: the VoxelGrid
  // keeps one point per 0.1 m voxel anyway. 1.5 m / 10 deg: each surface is still in ~10 scans;
  // on a simulated 60 s street drive (372 m) the dense points' median distance to the true
  // surfaces stays 0.29 m (0.30 at every keyframe: SPP GNSS dominates), with 39 % of the depth
  // keyframes and 34 % fewer points (thinner surfaces after the VoxelGrid); map build 18.9 ->
  // 7.9 s. 0 and 0: depth at every (n-th) keyframe.
  double min_spacing_m = 1.5;
  double min_rotation_deg = 10.0;
  StereoDepthConfig stereo;
  // Voxel size of the per-keyframe and the final VoxelGrid (issue 8: 0.1 m). Also bounds memory:
  // a keyframe keeps ~20-40 k points at 0.1 m instead of ~100 k raw half-size depth pixels.
  double voxel_size_m = 0.1;
  // StatisticalOutlierRemoval (Rusu 2008): a point whose mean distance to its 20 nearest
  // neighbours is beyond mean + 2 sigma of all such distances is a stray (PCL tutorial values).
  int sor_mean_k = 20;
  double sor_stddev_mul = 2.0;
};

struct OccupancyConfig {
  // 0.2 m (issue 8): twice the dense voxel, so each occupied voxel holds several dense points,
  // and the keyframe's ray casting stays within the per-keyframe budget.
  double resolution_m = 0.2;
  // Rays are cast up to this range (longer measurements clear free space up to it only). The
  // dense points end at stereo.max_range_m anyway; the margin lets sparse landmarks reach further.
  double max_range_m = 30.0;
};

struct MapConfig {
  SparseMapConfig sparse;
  DenseMapConfig dense;
  OccupancyConfig occupancy;
  void validate() const;  // throws InvalidInput naming the field
};

}  // namespace gvio::mapping
