#pragma once
// What loop closure keeps of a keyframe (no images): keypoints of the rectified left image with
// ORB descriptors (Rublee et al. 2011) at their pixels, a 3-D point in the left camera frame for
// those whose depth is known, and a tiny normalised thumbnail of the whole image for ranking
// candidates. The keypoints are the VIO front end's tracked corners (their stereo match or their
// window landmark gives the 3-D point: nothing is matched twice), plus optionally fresh ORB
// corners (2-D only) that give a query more chances to match.
// Descriptors are upright (angle 0): a road camera does not roll, and steered BRIEF's rotation
// invariance would only cost distinctiveness.
// The thumbnail is the image scaled to kThumbnailWidth x kThumbnailHeight, zero-mean and unit
// norm: the whole-image "tiny image" of Torralba et al. 2008 / SeqSLAM (Milford 2012); the dot
// product of two thumbnails is their normalised cross-correlation.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "odometry/measurements.hpp"

namespace gvio::mapping {

inline constexpr int kThumbnailWidth = 48;
inline constexpr int kThumbnailHeight = 16;

struct LoopFeatureConfig {
  // Fresh ORB corners added as 2-D keypoints (0: only the tracked corners); detected on
  // orb_levels pyramid levels with this FAST threshold.
  int orb_features = 0;
  int orb_levels = 2;
  int orb_fast_threshold = 20;
  // Depth range kept for 3-D points: stereo depth error grows as z^2 / (f b) (KITTI: ~0.5 m per
  // pixel of disparity at 30 m), and far points only blur the PnP.
  double min_depth_m = 1.0;
  double max_depth_m = 30.0;
  void validate() const;  // throws InvalidInput naming the key
};

// A keypoint handed to makeLoopKeyframe: a pixel of the rectified left image and, when known, its
// 3-D point in the left camera frame.
struct LoopPointInput {
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  bool has_point = false;
  Eigen::Vector3d p_c = Eigen::Vector3d::Zero();
};

struct LoopKeyframe {
  std::int64_t t_ns = 0;
  // Keypoints in the rectified left image; the first `points` of them have a 3-D point in p_c.
  std::vector<Eigen::Vector2f> px;
  cv::Mat descriptors;               // CV_8U, one 32-byte ORB row per keypoint
  std::vector<Eigen::Vector3f> p_c;  // left camera frame, size `points`
  std::size_t points = 0;
  std::vector<float> thumbnail;  // kThumbnailWidth x kThumbnailHeight, zero mean, unit norm

  [[nodiscard]] std::size_t memoryBytes() const;
};

// Normalised cross-correlation of two thumbnails, in [-1, 1]; 0 when either is empty or flat.
float thumbnailSimilarity(const LoopKeyframe& a, const LoopKeyframe& b);

// The keyframe's record from its rectified left image and keypoints (3-D points outside the
// depth range are kept as 2-D keypoints; keypoints too close to the border for a descriptor are
// dropped).
LoopKeyframe makeLoopKeyframe(std::int64_t t_ns, const cv::Mat& left,
                              const std::vector<LoopPointInput>& points,
                              const LoopFeatureConfig& config);

}  // namespace gvio::mapping
