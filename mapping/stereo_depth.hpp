#pragma once
// Dense depth from a rectified stereo pair: cv::StereoSGBM (semi-global matching, Hirschmueller,
// PAMI 2008) on a downscaled 8-bit pair, back-projected into the LEFT camera frame with the
// pixel's grey value as intensity. Only confident pixels survive: SGBM's uniqueness test, its
// left-right consistency check (disp12MaxDiff), its speckle filter and invalid disparities are
// dropped, then the depth is gated to [min_range_m, max_range_m].
#include <opencv2/calib3d.hpp>
#include <opencv2/core/mat.hpp>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "mapping/map_config.hpp"
#include "odometry/measurements.hpp"

namespace gvio::mapping {

using CameraCloud = pcl::PointCloud<pcl::PointXYZI>;  // left camera frame, m; intensity 0..255

class StereoDepth {
 public:
  // `left` is the rectified left camera (pinhole, no distortion); the right camera is the left
  // one moved by +baseline_m along its x axis. Throws InvalidInput for an invalid config, camera
  // or baseline.
  StereoDepth(const StereoDepthConfig& config, const CameraModel& left, double baseline_m);

  // 8-bit grey rectified images of the camera's size. An empty image (mono frame) gives no
  // points; a wrong size or type throws InvalidInput.
  [[nodiscard]] CameraCloud compute(const cv::Mat& left, const cv::Mat& right);

  // The last disparity map (CV_16S, 4 fractional bits, downscaled size): for tests and views.
  [[nodiscard]] const cv::Mat& lastDisparity() const { return disparity_; }

 private:
  StereoDepthConfig config_;
  CameraModel camera_;
  double baseline_m_ = 0.0;
  cv::Size scaled_size_;
  double fx_ = 0.0, fy_ = 0.0, cx_ = 0.0, cy_ = 0.0;  // intrinsics of the downscaled image
  cv::Ptr<cv::StereoSGBM> sgbm_;
  cv::Mat small_left_, small_right_, disparity_;
};

// pcl::VoxelGrid: one point (centroid, mean intensity) per occupied voxel of size leaf_m.
[[nodiscard]] CameraCloud voxelDownsample(const CameraCloud& cloud, double leaf_m);

}  // namespace gvio::mapping
