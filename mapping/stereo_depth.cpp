#include "mapping/stereo_depth.hpp"

#include <cmath>
#include <cstdint>
#include <string>

#include <pcl/filters/voxel_grid.h>
#include <opencv2/imgproc.hpp>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

void checkImage(const cv::Mat& image, const CameraModel& camera, const char* which) {
  if (image.type() != CV_8UC1 || image.cols != camera.width_px || image.rows != camera.height_px) {
    throw InvalidInput(std::string("stereo depth: ") + which + " image must be 8-bit grey of " +
                       std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px));
  }
}

}  // namespace

StereoDepth::StereoDepth(const StereoDepthConfig& config, const CameraModel& left,
                         double baseline_m)
    : config_(config), camera_(left), baseline_m_(baseline_m) {
  if (left.width_px <= 0 || left.height_px <= 0 || !(left.fx > 0.0) || !(left.fy > 0.0)) {
    throw InvalidInput("stereo depth: camera '" + left.name +
                       "' has no valid size or focal length");
  }
  if (!std::isfinite(baseline_m) || baseline_m <= 0.0) {
    throw InvalidInput("stereo depth: baseline must be > 0 m");
  }
  const int width = static_cast<int>(std::lround(left.width_px * config.downscale));
  const int height = static_cast<int>(std::lround(left.height_px * config.downscale));
  if (width <= config.num_disparities || height < config.block_size) {
    throw InvalidInput("stereo depth: downscaled image too small for the disparity range");
  }
  scaled_size_ = cv::Size(width, height);
  // cv::resize maps pixel centres: x_small + 0.5 = (x + 0.5) * scale.
  const double sx = static_cast<double>(width) / left.width_px;
  const double sy = static_cast<double>(height) / left.height_px;
  fx_ = left.fx * sx;
  fy_ = left.fy * sy;
  cx_ = (left.cx + 0.5) * sx - 0.5;
  cy_ = (left.cy + 0.5) * sy - 0.5;

  const int area = config.block_size * config.block_size;  // one channel
  sgbm_ = cv::StereoSGBM::create(0, config.num_disparities, config.block_size, 8 * area, 32 * area,
                                 config.disp12_max_diff, config.pre_filter_cap,
                                 config.uniqueness_ratio, config.speckle_window_size,
                                 config.speckle_range, cv::StereoSGBM::MODE_SGBM_3WAY);
}

CameraCloud StereoDepth::compute(const cv::Mat& left, const cv::Mat& right) {
  CameraCloud cloud;
  disparity_.release();
  if (left.empty() || right.empty()) return cloud;
  checkImage(left, camera_, "left");
  checkImage(right, camera_, "right");

  if (scaled_size_ == left.size()) {
    small_left_ = left;
    small_right_ = right;
  } else {
    // Area averaging: the anti-aliased downscale SGBM's census-like cost needs.
    cv::resize(left, small_left_, scaled_size_, 0.0, 0.0, cv::INTER_AREA);
    cv::resize(right, small_right_, scaled_size_, 0.0, 0.0, cv::INTER_AREA);
  }
  sgbm_->compute(small_left_, small_right_, disparity_);

  // z = f b / d; pixels with d <= 0 are SGBM's "no match" (minDisparity - 1 after the checks).
  const double fb = fx_ * baseline_m_;
  const double d_min = fb / config_.max_range_m;  // far limit -> smallest disparity
  const double d_max = fb / config_.min_range_m;
  cloud.reserve(static_cast<std::size_t>(disparity_.total() / 2));
  for (int v = 0; v < disparity_.rows; ++v) {
    const auto* d_row = disparity_.ptr<std::int16_t>(v);
    const auto* i_row = small_left_.ptr<std::uint8_t>(v);
    for (int u = 0; u < disparity_.cols; ++u) {
      if (d_row[u] <= 0) continue;
      const double d = d_row[u] / 16.0;
      if (d < d_min || d > d_max) continue;
      const double z = fb / d;
      pcl::PointXYZI p;
      p.x = static_cast<float>((u - cx_) * z / fx_);
      p.y = static_cast<float>((v - cy_) * z / fy_);
      p.z = static_cast<float>(z);
      p.intensity = static_cast<float>(i_row[u]);
      cloud.push_back(p);
    }
  }
  return cloud;
}

CameraCloud voxelDownsample(const CameraCloud& cloud, double leaf_m) {
  CameraCloud out;
  if (cloud.empty()) return out;
  pcl::VoxelGrid<pcl::PointXYZI> grid;
  // Non-owning pointer: PCL filters take shared pointers, the caller keeps the cloud alive.
  grid.setInputCloud(CameraCloud::ConstPtr(&cloud, [](const CameraCloud*) {}));
  const auto leaf = static_cast<float>(leaf_m);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.filter(out);
  return out;
}

}  // namespace gvio::mapping
