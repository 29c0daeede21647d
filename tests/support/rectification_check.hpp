#pragma once
// Checks of odometry::Rectifier against the raw camera models, shared by the radtan and fisheye
// rectifier tests: points projected through the raw (distorted) models, and images whose pixels
// hold their own coordinates, which show after rectification where each rectified pixel sampled
// the raw image.
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "odometry/error.hpp"
#include "odometry/measurements.hpp"
#include "odometry/rectifier.hpp"

namespace gvio::test {

inline Eigen::Vector2d projectPinhole(const CameraModel& cam, const Eigen::Vector3d& p_b) {
  const Eigen::Vector3d p_c = cam.T_b_c.inverse() * p_b;
  return {cam.fx * p_c.x() / p_c.z() + cam.cx, cam.fy * p_c.y() / p_c.z() + cam.cy};
}

// Through the raw, distorted model, as OpenCV defines it: cv::projectPoints for radtan,
// cv::fisheye::projectPoints for equidistant (Kannala-Brandt) cameras.
inline Eigen::Vector2d projectRaw(const CameraModel& cam, const Eigen::Vector3d& p_b) {
  const Eigen::Isometry3d T_c_b = cam.T_b_c.inverse();
  cv::Mat R(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R.at<double>(r, c) = T_c_b.linear()(r, c);
    tvec.at<double>(r) = T_c_b.translation()(r);
  }
  cv::Rodrigues(R, rvec);
  const cv::Mat K = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  const std::vector<cv::Point3d> points{{p_b.x(), p_b.y(), p_b.z()}};
  std::vector<cv::Point2d> px;
  if (cam.distortion_model == Distortion::kEquidistant) {
    cv::fisheye::projectPoints(points, px, rvec, tvec, K, cam.distortion);
  } else {
    cv::projectPoints(points, rvec, tvec, K, cam.distortion, px);
  }
  return {px[0].x, px[0].y};
}

inline bool inside(const CameraModel& cam, const Eigen::Vector2d& px, double margin) {
  return px.x() >= margin && px.y() >= margin && px.x() <= cam.width_px - 1 - margin &&
         px.y() <= cam.height_px - 1 - margin;
}

// Points in front of the rectified left camera (2-30 m), seen inside every image (raw and
// rectified, left and right) with a 2 px margin.
inline std::vector<Eigen::Vector3d> visiblePoints(const odometry::Rectifier& rect,
                                                  const CameraModel& raw_left,
                                                  const std::optional<CameraModel>& raw_right) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const CameraModel& left = rect.left();
  std::vector<Eigen::Vector3d> points;
  while (points.size() < 300) {
    const double depth = 2.0 + 28.0 * u(rng);
    const Eigen::Vector3d p_c((left.width_px * u(rng) - left.cx) / left.fx * depth,
                              (left.height_px * u(rng) - left.cy) / left.fy * depth, depth);
    const Eigen::Vector3d p_b = left.T_b_c * p_c;
    bool ok = inside(left, projectPinhole(left, p_b), 2) &&
              inside(raw_left, projectRaw(raw_left, p_b), 2);
    if (raw_right) {
      ok = ok && inside(*rect.right(), projectPinhole(*rect.right(), p_b), 2) &&
           inside(*raw_right, projectRaw(*raw_right, p_b), 2);
    }
    if (ok) points.push_back(p_b);
  }
  return points;
}

// The rectified stereo contract, whatever the lens model: no distortion, one K, the camera
// centres where they were, the raw baseline, the right camera the left one moved along its own x
// axis, and every visible point on the same row in both images with a positive disparity.
inline void expectStereoContract(const odometry::Rectifier& rect, const CameraModel& raw_l,
                                 const CameraModel& raw_r) {
  ASSERT_TRUE(rect.isStereo());
  const CameraModel& l = rect.left();
  const CameraModel& r = *rect.right();
  EXPECT_TRUE(l.distortion.empty());
  EXPECT_TRUE(r.distortion.empty());
  EXPECT_DOUBLE_EQ(l.fx, r.fx);
  EXPECT_DOUBLE_EQ(l.fy, r.fy);
  EXPECT_DOUBLE_EQ(l.cx, r.cx);
  EXPECT_DOUBLE_EQ(l.cy, r.cy);
  // Rectification turns the cameras about their centres: the centres stay where they were.
  EXPECT_LT((l.T_b_c.translation() - raw_l.T_b_c.translation()).norm(), 1e-12);
  EXPECT_LT((r.T_b_c.translation() - raw_r.T_b_c.translation()).norm(), 1e-9);
  const double raw_baseline = (raw_r.T_b_c.translation() - raw_l.T_b_c.translation()).norm();
  EXPECT_NEAR(rect.baselineM(), raw_baseline, 1e-12);
  // The right camera differs from the left only by +baseline along the left x axis.
  const Eigen::Isometry3d T_l_r = l.T_b_c.inverse() * r.T_b_c;
  EXPECT_LT((T_l_r.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((T_l_r.translation() - Eigen::Vector3d(rect.baselineM(), 0, 0)).norm(), 1e-12);
  for (const Eigen::Vector3d& p_b : visiblePoints(rect, raw_l, raw_r)) {
    const Eigen::Vector2d pl = projectPinhole(l, p_b), pr = projectPinhole(r, p_b);
    EXPECT_NEAR(pl.y(), pr.y(), 0.05);
    EXPECT_GT(pl.x(), pr.x());
  }
}

// An image whose pixels hold their own x (or y) coordinate: after rectification, each pixel
// holds the raw position it sampled.
inline cv::Mat coordinateImage(const CameraModel& cam, bool y) {
  cv::Mat image(cam.height_px, cam.width_px, CV_32F);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) image.at<float>(r, c) = static_cast<float>(y ? r : c);
  }
  return image;
}

inline double bilinear(const cv::Mat& image, const Eigen::Vector2d& px) {
  const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
  const double ax = px.x() - x0, ay = px.y() - y0;
  auto at = [&](int x, int y) { return static_cast<double>(image.at<float>(y, x)); };
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

// Where the rectified image of `which` camera samples the raw one at the rectified projection of
// each point, against the raw model's projection: the worst miss in px.
inline double worstMapError(const odometry::Rectifier& rect, const CameraModel& raw_left,
                            const std::optional<CameraModel>& raw_right, bool right_camera) {
  const CameraModel& raw = right_camera ? *raw_right : raw_left;
  const CameraModel& model = right_camera ? *rect.right() : rect.left();
  odometry::RectifiedImages xs, ys;
  if (raw_right) {
    xs = rect.rectify(coordinateImage(raw_left, false), coordinateImage(*raw_right, false));
    ys = rect.rectify(coordinateImage(raw_left, true), coordinateImage(*raw_right, true));
  } else {
    xs = rect.rectify(coordinateImage(raw_left, false));
    ys = rect.rectify(coordinateImage(raw_left, true));
  }
  const cv::Mat& x_img = right_camera ? xs.right : xs.left;
  const cv::Mat& y_img = right_camera ? ys.right : ys.left;
  double worst = 0.0;
  for (const Eigen::Vector3d& p_b : visiblePoints(rect, raw_left, raw_right)) {
    const Eigen::Vector2d rectified = projectPinhole(model, p_b);
    const Eigen::Vector2d sampled(bilinear(x_img, rectified), bilinear(y_img, rectified));
    worst = std::max(worst, (sampled - projectRaw(raw, p_b)).norm());
  }
  return worst;
}

// The message of the InvalidInput a rectifier for these cameras throws; "" when it builds.
inline std::string rectifierError(const CameraModel& left,
                                  const std::optional<CameraModel>& right) {
  try {
    const odometry::Rectifier rect(left, right);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

}  // namespace gvio::test
