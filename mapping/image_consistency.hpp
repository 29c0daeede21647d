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
// Both are summarised per view; flagOutliers() marks the views far below the agreement typical of
// their stretch of the drive (how well a correct map matches its image varies with the world's
// texture and depth, slowly along a drive), or far below the whole drive's, so a fault stands
// out whatever the world looks like.
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
  // size (f b = 194 px m). On the simulated demo drive with true poses 88 % of the pixels agree
  // (0.5 px: 62 %, too close to the noise to tell a fault from it).
  double disparity_tolerance_px = 1.0;
  double depth_tolerance_m = 0.1;  // never tighter than this (one voxel of the map)
  int min_patches = 10;            // fewer valid patches: the view's ZNCC is not scored
  int min_depth_pixels = 500;      // fewer pixels with both depths: no depth agreement
  // A view is flagged when its ZNCC falls below the median of the views within +-local_window_s/2
  // by more than flag_sigmas robust sigmas of all such differences (1.4826 MAD), or below the
  // median of the whole drive by more than flag_sigmas robust sigmas of its ZNCCs. A sigma is
  // never below min_flag_sigma (a drive whose views all agree equally would flag noise). 10 s:
  // several times a fault's few seconds, short against a change of scenery.
  double local_window_s = 10.0;
  double flag_sigmas = 4.0;
  double min_flag_sigma = 0.03;
  // And whatever the drive: a map that does not correlate with its image (ZNCC near 0) or whose
  // depth disagrees on most pixels is wrong there. These floors catch a fault long enough to move
  // the medians; they sit below a correct map's scores (simulated KITTI-00 with true poses: ZNCC
  // 0.33-0.69, depth agreement 0.39-0.98).
  // The depth agreement flags through its floor only: with true poses it dips by 4 robust sigmas
  // at turns and near objects (27 KITTI-00 keyframes flagged, all on depth alone), while every
  // fault seen (poses moved, the VIO's errors) lowered the ZNCC first.
  double min_ncc = 0.15;
  double min_depth_agreement = 0.3;
  std::size_t min_views_to_flag = 8;
  // A view the render covers much less than is typical of the drive (the first and last keyframes
  // see the map from one side only; a turn into an unmapped street) scores lower with a correct
  // map, since its patches are sparser and fewer: it is flagged by the floors only.
  double min_relative_coverage = 0.75;  // too few views for a robust spread: nothing is flagged

  void validate() const;  // throws InvalidInput naming the field
};

struct ViewScore {
  double ncc = std::numeric_limits<double>::quiet_NaN();  // mean patch ZNCC, NaN: not scored
  int patches = 0;                                        // patches that counted
  double coverage = 0.0;                                  // share of the image the render covers
  double depth_agreement = std::numeric_limits<double>::quiet_NaN();  // NaN: not scored
  std::size_t depth_pixels = 0;  // pixels with a rendered and a stereo depth

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

// The flag thresholds of one score.
struct ScoreThresholds {
  double median = std::numeric_limits<double>::quiet_NaN();  // of the whole drive
  double global = -std::numeric_limits<double>::infinity();  // flagged below (at least the floor)
  std::vector<double> local;  // per view: flagged below (-inf where there are too few views)
};

struct FlaggedViews {
  std::vector<bool> flagged;  // per view
  ScoreThresholds ncc, depth;
};

// t_s: the views' times (s), ascending. Unscored values never flag.
[[nodiscard]] FlaggedViews flagOutliers(const std::vector<ViewScore>& views,
                                        const std::vector<double>& t_s,
                                        const ImageConsistencyConfig& config);

struct ViewStretch {
  std::size_t first = 0, last = 0;  // view indices, inclusive
};

// Runs of flagged views, joined across gaps of at most max_gap unflagged views.
[[nodiscard]] std::vector<ViewStretch> flaggedStretches(const std::vector<bool>& flagged,
                                                        std::size_t max_gap = 1);

}  // namespace gvio::mapping
