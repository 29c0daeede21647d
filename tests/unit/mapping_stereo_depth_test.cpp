// Dense stereo depth: a textured fronto-parallel plane seen with a known disparity must come back
// at z = f b / d; the range gate, empty and textureless images, and the per-keyframe VoxelGrid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapping/stereo_depth.hpp"
#include "odometry/error.hpp"
#include "support/kitti_camera.hpp"

namespace gvio::mapping {
namespace {

CameraModel kittiCamera() {
  return test::kittiRectifiedCamera();
}
constexpr double kBaseline_m = test::kKittiBaselineM;

// Blurred uniform noise: texture at several scales, like asphalt or a facade.
cv::Mat texture(int rows, int cols, unsigned seed) {
  cv::Mat noise(rows, cols, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat blurred;
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), 1.2);
  cv::Mat out;
  cv::normalize(blurred, out, 0, 255, cv::NORM_MINMAX);
  return out;
}

// Left image and the right image of a fronto-parallel plane at disparity d_px (full size):
// right(u) = left(u + d). The last d columns of the right image get fresh texture.
std::pair<cv::Mat, cv::Mat> planePair(const CameraModel& c, int d_px) {
  const cv::Mat left = texture(c.height_px, c.width_px, 7);
  cv::Mat right = texture(c.height_px, c.width_px, 8);
  left.colRange(d_px, c.width_px).copyTo(right.colRange(0, c.width_px - d_px));
  return {left, right};
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(MappingStereoDepth, PlaneAtKnownDisparityGivesFbOverD) {
  const CameraModel cam = kittiCamera();
  const auto [left, right] = planePair(cam, 40);
  StereoDepth depth(StereoDepthConfig{}, cam, kBaseline_m);
  const CameraCloud cloud = depth.compute(left, right);
  const double z_true = cam.fx * kBaseline_m / 40.0;  // 9.70 m

  // Most of the image matches (all but the left border SGBM cannot search).
  const double valid_fraction =
      static_cast<double>(cloud.size()) / (0.25 * cam.width_px * cam.height_px);
  EXPECT_GT(valid_fraction, 0.7);
  std::vector<double> z, x_err, y_err;
  for (const auto& p : cloud) {
    z.push_back(p.z);
    EXPECT_NEAR(p.z, z_true, 0.03 * z_true);
  }
  EXPECT_NEAR(median(z), z_true, 0.005 * z_true);
  // The plane spans the camera's field of view at that depth (back-projection uses the downscaled
  // intrinsics consistently): x from -(cx) z / f to (w - cx) z / f.
  float x_min = 1e9f, x_max = -1e9f, y_min = 1e9f, y_max = -1e9f;
  for (const auto& p : cloud) {
    x_min = std::min(x_min, p.x);
    x_max = std::max(x_max, p.x);
    y_min = std::min(y_min, p.y);
    y_max = std::max(y_max, p.y);
    EXPECT_GE(p.intensity, 0.0f);
    EXPECT_LE(p.intensity, 255.0f);
  }
  EXPECT_NEAR(x_max, (cam.width_px - cam.cx) * z_true / cam.fx, 0.1);
  EXPECT_NEAR(y_min, -cam.cy * z_true / cam.fy, 0.2);
  EXPECT_NEAR(y_max, (cam.height_px - cam.cy) * z_true / cam.fy, 0.2);
  EXPECT_GT(x_min, (64 * 2 - cam.cx) * z_true / cam.fx - 0.2);  // 64 half-size px border
}

TEST(MappingStereoDepth, FullResolutionSubpixelDisparity) {
  // At full size SGBM's subpixel disparity must hold a shift of 30 px to 0.5 %.
  const CameraModel cam = kittiCamera();
  const auto [left, right] = planePair(cam, 30);
  StereoDepthConfig config;
  config.downscale = 1.0;
  config.num_disparities = 64;
  StereoDepth depth(config, cam, kBaseline_m);
  const CameraCloud cloud = depth.compute(left, right);
  ASSERT_GT(cloud.size(), 100000u);
  std::vector<double> z;
  for (const auto& p : cloud) z.push_back(p.z);
  EXPECT_NEAR(median(z), cam.fx * kBaseline_m / 30.0, 0.005 * cam.fx * kBaseline_m / 30.0);
}

TEST(MappingStereoDepth, RangeGateDropsThePlane) {
  const CameraModel cam = kittiCamera();
  const auto [left, right] = planePair(cam, 40);  // 9.70 m
  StereoDepthConfig near_only;
  near_only.max_range_m = 8.0;
  EXPECT_EQ(StereoDepth(near_only, cam, kBaseline_m).compute(left, right).size(), 0u);
  StereoDepthConfig far_only;
  far_only.min_range_m = 11.0;
  far_only.max_range_m = 20.0;
  EXPECT_EQ(StereoDepth(far_only, cam, kBaseline_m).compute(left, right).size(), 0u);
  StereoDepthConfig around;
  around.min_range_m = 9.0;
  around.max_range_m = 10.5;
  EXPECT_GT(StereoDepth(around, cam, kBaseline_m).compute(left, right).size(), 50000u);
}

TEST(MappingStereoDepth, EmptyAndTexturelessImagesGiveNoPoints) {
  const CameraModel cam = kittiCamera();
  StereoDepth depth(StereoDepthConfig{}, cam, kBaseline_m);
  EXPECT_TRUE(depth.compute(cv::Mat(), cv::Mat()).empty());
  const cv::Mat left = texture(cam.height_px, cam.width_px, 3);
  EXPECT_TRUE(depth.compute(left, cv::Mat()).empty());
  const cv::Mat black = cv::Mat::zeros(cam.height_px, cam.width_px, CV_8UC1);
  EXPECT_TRUE(depth.compute(black, black).empty());
  const cv::Mat grey(cam.height_px, cam.width_px, CV_8UC1, cv::Scalar(128));
  EXPECT_TRUE(depth.compute(grey, grey).empty());
}

TEST(MappingStereoDepth, RejectsWrongImagesAndCameras) {
  const CameraModel cam = kittiCamera();
  StereoDepth depth(StereoDepthConfig{}, cam, kBaseline_m);
  const cv::Mat small(100, 100, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(std::ignore = depth.compute(small, small), InvalidInput);
  const cv::Mat colour(cam.height_px, cam.width_px, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_THROW(std::ignore = depth.compute(colour, colour), InvalidInput);
  EXPECT_THROW(StereoDepth(StereoDepthConfig{}, cam, 0.0), InvalidInput);
  CameraModel no_focal = cam;
  no_focal.fx = 0.0;
  EXPECT_THROW(StereoDepth(StereoDepthConfig{}, no_focal, kBaseline_m), InvalidInput);
}

TEST(MappingStereoDepth, VoxelDownsampleKeepsOnePointPerVoxel) {
  const CameraModel cam = kittiCamera();
  const auto [left, right] = planePair(cam, 40);
  StereoDepth depth(StereoDepthConfig{}, cam, kBaseline_m);
  const CameraCloud cloud = depth.compute(left, right);
  const double leaf = 0.1;
  const CameraCloud down = voxelDownsample(cloud, leaf);
  ASSERT_FALSE(down.empty());
  EXPECT_LT(down.size(), cloud.size() / 2);
  // pcl::VoxelGrid's own cell formula (float): one output point per occupied input voxel.
  const float inverse_leaf = 1.0f / static_cast<float>(leaf);
  const auto voxel = [inverse_leaf](const pcl::PointXYZI& p) {
    return std::tuple<long, long, long>(static_cast<long>(std::floor(p.x * inverse_leaf)),
                                        static_cast<long>(std::floor(p.y * inverse_leaf)),
                                        static_cast<long>(std::floor(p.z * inverse_leaf)));
  };
  std::set<std::tuple<long, long, long>> input_voxels, output_voxels;
  for (const auto& p : cloud) input_voxels.insert(voxel(p));
  for (const auto& p : down) output_voxels.insert(voxel(p));
  EXPECT_EQ(down.size(), input_voxels.size());
  // Centroids stay inside their voxel (a float rounding on a boundary may move a rare one).
  EXPECT_GE(static_cast<double>(output_voxels.size()), 0.999 * static_cast<double>(down.size()));
  EXPECT_TRUE(voxelDownsample(CameraCloud(), leaf).empty());
}

}  // namespace
}  // namespace gvio::mapping
