#pragma once
// Camera pose from 3-D/2-D correspondences: OpenCV's solvePnPRansac (iterative, started from a
// guess) with the pose in and out as Eigen, shared by the visual pose prediction and the
// monocular SfM.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

namespace gvio::odometry {

struct PnpResult {
  Eigen::Isometry3d T_c_w = Eigen::Isometry3d::Identity();  // world point -> camera frame
  int inliers = 0;
};

// `K` maps camera coordinates to `image` (the identity for normalised coordinates);
// `threshold` is the RANSAC reprojection threshold in `image` units. nullopt when OpenCV finds no
// model or the result is not finite.
std::optional<PnpResult> pnpRansac(const std::vector<cv::Point3d>& object,
                                   const std::vector<cv::Point2d>& image, const cv::Matx33d& K,
                                   const Eigen::Isometry3d& T_c_w_guess, float threshold);

}  // namespace gvio::odometry
