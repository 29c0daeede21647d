#pragma once
// Scores of a map against a camera image it was not built from (gvio consistency --images): the
// map rendered from the camera's pose (grey level and depth per pixel) against the recorded,
// rectified image and that camera's own stereo depth.
//  - Photometric agreement: zero-mean normalised cross-correlation (ZNCC) over square patches
//    where the render covers the patch and both images have texture. ZNCC is invariant to gain
//    and offset (auto-exposure, a different keyframe's exposure in the map's grey levels), so
//    only structure counts: a map drawn a few pixels off its image decorrelates.
//  - Geometric agreement: the share of pixels with both a rendered and a stereo depth whose two
//    depths agree, compared as disparities d = f b / z (stereo's error is uniform in disparity,
//    Hartley & Zisserman 2003, sec. 12.6): |f b / z_r - f b / z_s| <= tolerance, i.e. a depth
//    tolerance of about z^2 tolerance / (f b), plus a floor of one voxel.
// Both are means over a grid of patches, with standard errors from the patches' spread; which
// views they flag is mapping/view_flags.hpp's.
// No file I/O.
#include <cstddef>
#include <limits>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace gvio::mapping {

struct ImageConsistencyConfig {
  int patch_px = 16;                // side of the square ZNCC patches (a grid, no overlap)
  double min_patch_coverage = 0.8;  // share of a patch the render must cover
  double min_patch_stddev = 4.0;    // grey levels, in both images (flat patches say nothing)

  // Disparity tolerance in the pixels of scoreView's focal_baseline_px_m = f b (SGBM's downscaled
  // image): 1 px is about three sigmas of the difference of two SGBM disparities (each with
  // SGBM's ~1/4 px sub-pixel error, plus the 0.1 m voxels), i.e. 0.52 m at 10 m on KITTI at half
  // size (f b = 194 px m).
  double disparity_tolerance_px = 1.0;
  double depth_tolerance_m = 0.1;  // never tighter than this (one voxel of the map)

  // The evidence a score needs. Both scores are means over the patch grid, so each has a standard
  // error from the spread of its patches: ZNCC over the textured patches the drawing covers, depth
  // agreement over the patches holding at least min_cell_depth_pixels pixels with both depths
  // (pixels of one SGBM block are not independent, patches nearly are). Fewer patches than these
  // minimums: "not enough evidence", never a flag.
  int min_patches = 10;
  int min_cell_depth_pixels = 32;
  int min_depth_cells = 10;

  // The flag rule (flagOutliers), the same for both scores. A view's score s is compared with the
  // median m of the views within +-local_window_s/2 (the scenery changes slowly along a drive), or
  // with the whole drive's median where fewer than min_views_to_flag views are that near. Its
  // residual s - m is judged against the standard error se it would have if it were correct (the
  // drive's median per-patch spread over the square root of this view's patches: its own spread
  // grows with a fault) and the spread tau that correct views show around their neighbours beyond
  // their errors (estimated from the drive: tau^2 = (1.4826 MAD of the residuals)^2 - median
  // se^2). A view is flagged when
  // (s - m) / sqrt(tau^2 + se^2) < -k x the robust spread of these standardised residuals over the
  // drive (at least 1): a normal score flags Phi(-k) of correct views, 3e-5 at k = 4; the benchmark
  // measures the rate on each world (tests/bench/image_check_matrix.sh). k is flag_sigmas for the
  // ZNCC and depth_flag_sigmas for the depth agreement, whose residuals have heavier tails (a
  // share of pixels of whole surfaces: a parked car or a turn moves many at once). min_flag_sigma
  // keeps a drive whose views all agree alike from flagging noise.
  // What is typical also depends on how near the drawn map is: a near surface is magnified (one
  // 0.1 m voxel spans 8 px at 9 m on KITTI, 3.6 px at 20 m) and was measured by the sources from
  // other directions, so a correct map reproduces it less well. With true poses on the seed-2
  // KITTI-00 window and similar_views 0 (tests/bench/image_check_sigmas.py), the keyframes whose
  // drawn map points lay at a median under 15 m (slow sharp turns at junctions, facing a wall: 18
  // of 259 on sparse texture) scored a median 3.0 ZNCC sigmas below their neighbours in time
  // (1.3 on vegetation), and every false flag was among them. So a view's residual
  // s - m is judged against the median and the spread of the residuals of the similar_views views
  // whose drawn depth (ViewScore::drawn_depth_m) is nearest its own (in 1 / depth, the
  // magnification), among the views more than local_window_s away in time (a faulty stretch's
  // views are alike and must not be each other's reference), the spread never taken tighter than
  // the whole drive's (a spread of a few dozen views is itself uncertain). A displaced pose moves
  // the map in the image, not its depth, so a fault still stands out among its peers. Fewer such
  // views, or 0: the view is judged against the whole drive alike.
  std::size_t similar_views = 30;
  double local_window_s = 10.0;
  double flag_sigmas = 4.0;
  double depth_flag_sigmas = 5.0;
  double min_flag_sigma = 0.02;
  std::size_t min_views_to_flag = 8;
  // Whatever the drive: a map that does not correlate with its image (ZNCC significantly below
  // min_ncc: s + flag_sigmas x se < min_ncc) is wrong there. Depth agreement has no such floor: its
  // level depends on how well SGBM matches the world's surfaces.
  double min_ncc = 0.15;

  void validate() const;  // throws InvalidInput naming the field
};

struct ViewScore {
  double ncc = std::numeric_limits<double>::quiet_NaN();     // mean patch ZNCC, NaN: not scored
  double ncc_se = std::numeric_limits<double>::quiet_NaN();  // its standard error
  int patches = 0;                                           // patches that counted
  double coverage = 0.0;                                     // share of the image the render covers
  // Share of the pixels with both depths that agree; NaN: not scored.
  double depth_agreement = std::numeric_limits<double>::quiet_NaN();
  double depth_se = std::numeric_limits<double>::quiet_NaN();  // its standard error
  int depth_cells = 0;           // patches with enough pixels of both depths
  std::size_t depth_pixels = 0;  // pixels with a rendered and a stereo depth
  // Set by the caller: the median depth (m) of the map points drawn in view (the nearest one per
  // pixel), NaN: none known. The flag rule compares views drawn at similar depths
  // (ImageConsistencyConfig::similar_views).
  double drawn_depth_m = std::numeric_limits<double>::quiet_NaN();
  // Set by the caller: the map in view was measured only from behind the camera (no source
  // keyframe ahead of it: a forward camera's last keyframes of a drive). Its scores are biased
  // low (the surfaces ahead were seen from farther away, if at all), so flagOutliers judges it
  // by the ZNCC floor alone and leaves it out of what is typical.
  bool one_sided = false;

  [[nodiscard]] bool hasNcc() const { return ncc == ncc; }
  [[nodiscard]] bool hasDepth() const { return depth_agreement == depth_agreement; }
};

// recorded, rendered: CV_8UC1 of one size; covered: CV_8UC1 (non-zero where the render drew);
// rendered_depth_m, stereo_depth_m: CV_32FC1 camera-z depths, 0 (or not finite) where none.
// focal_baseline_px_m: f b of the stereo that measured the depths (f in the pixels of the
// disparity). Throws InvalidInput for mismatched sizes or types.
[[nodiscard]] ViewScore scoreView(const cv::Mat& recorded, const cv::Mat& rendered,
                                  const cv::Mat& covered, const cv::Mat& rendered_depth_m,
                                  const cv::Mat& stereo_depth_m, double focal_baseline_px_m,
                                  const ImageConsistencyConfig& config);

// The depth tolerance at depth z (see the header comment).
[[nodiscard]] double depthTolerance(double z_m, double focal_baseline_px_m,
                                    const ImageConsistencyConfig& config);

// ZNCC of two CV_8UC1 patches over the pixels where `mask` is non-zero; NaN when either has a
// standard deviation below min_stddev or fewer than 2 pixels count.
[[nodiscard]] double maskedZncc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask,
                                double min_stddev);

}  // namespace gvio::mapping
