// odometry::Rectifier on synthetic rigs: a distorted EuRoC-like stereo pair with a rotation between
// the cameras (rows align, and the rectified images sample the originals exactly where the
// original models project a point), a distorted mono camera, and already rectified KITTI-like
// cameras that pass through untouched.
#include "odometry/rectifier.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "odometry/error.hpp"
#include "support/euroc_camera.hpp"
#include "support/rectification_check.hpp"

namespace gvio::odometry {
namespace {
using test::eurocCam0;
using test::eurocCam1;
using test::expectStereoContract;
using test::projectPinhole;
using test::rectifierError;
using test::visiblePoints;
using test::worstMapError;
using testing::HasSubstr;

// KITTI's rectified grey pair: no distortion, one K, cam1 0.537 m along cam0's x axis.
CameraModel kittiCam0() {
  CameraModel c;
  c.name = "image_00";
  c.width_px = 1241;
  c.height_px = 376;
  c.fx = c.fy = 718.856, c.cx = 607.1928, c.cy = 185.2157;
  Eigen::Matrix3d R;  // camera x right, y down, z forward in a body x forward, z up
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  c.T_b_c = test::orthonormalPose(R, {1.08, -0.32, 0.73});
  return c;
}

CameraModel kittiCam1() {
  CameraModel c = kittiCam0();
  c.name = "image_01";
  c.T_b_c = c.T_b_c * Eigen::Translation3d(0.537, 0.0, 0.0);
  return c;
}

TEST(RectifierTest, StereoRigGetsOneKAndRowAlignedCameras) {
  const CameraModel raw_l = eurocCam0(), raw_r = eurocCam1();
  const Rectifier rect(raw_l, raw_r);
  EXPECT_FALSE(rect.isIdentity());
  ASSERT_TRUE(rect.isStereo());
  expectStereoContract(rect, raw_l, raw_r);
  EXPECT_EQ(rect.left().width_px, 752);
  EXPECT_EQ(rect.right()->height_px, 480);
  EXPECT_EQ(rect.right()->name, "cam1");
  EXPECT_NEAR(rect.baselineM(), 0.1101, 1e-3);
}

// The rectified models and the rectified images agree: a point projected by a rectified model
// lands on the pixel that was resampled from where the original model projects it.
TEST(RectifierTest, StereoMapsSampleWhereOriginalModelsProject) {
  const CameraModel raw_l = eurocCam0(), raw_r = eurocCam1();
  const Rectifier rect(raw_l, raw_r);
  EXPECT_LT(worstMapError(rect, raw_l, raw_r, false), 0.05);
  EXPECT_LT(worstMapError(rect, raw_l, raw_r, true), 0.05);
}

TEST(RectifierTest, DistortedMonoCameraIsUndistorted) {
  const CameraModel raw = eurocCam0();
  const Rectifier rect(raw);
  EXPECT_FALSE(rect.isIdentity());
  EXPECT_FALSE(rect.isStereo());
  EXPECT_FALSE(rect.right());
  EXPECT_TRUE(rect.left().distortion.empty());
  EXPECT_TRUE(rect.left().T_b_c.isApprox(raw.T_b_c, 1e-15));
  EXPECT_LT(worstMapError(rect, raw, std::nullopt, false), 0.05);
  // 8-bit grey in, 8-bit grey of the same size out, with no dark border or seam anywhere.
  const cv::Mat grey(raw.height_px, raw.width_px, CV_8U, cv::Scalar(200));
  const RectifiedImages out = rect.rectify(grey);
  EXPECT_EQ(out.left.type(), CV_8U);
  EXPECT_EQ(out.left.size(), grey.size());
  EXPECT_TRUE(out.right.empty());
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(out.left, &lo, &hi);
  EXPECT_EQ(lo, 200.0);
  EXPECT_EQ(hi, 200.0);
}

// ROS's rational_polynomial (OpenCV's 8 coefficients k1 k2 p1 p2 k3 k4 k5 k6), as a ROS 2 bag's
// CameraInfo states it: rectified like the 5-coefficient model, the maps sampling where the
// 8-coefficient model projects.
TEST(RectifierTest, RationalPolynomialCamerasAreRectified) {
  CameraModel raw_l = eurocCam0(), raw_r = eurocCam1();
  for (CameraModel* c : {&raw_l, &raw_r}) {
    c->distortion = {c->distortion[0],
                     c->distortion[1],
                     c->distortion[2],
                     c->distortion[3],
                     0.01,
                     0.05,
                     -0.02,
                     0.01};
  }
  const Rectifier mono(raw_l);
  EXPECT_TRUE(mono.left().distortion.empty());
  EXPECT_LT(worstMapError(mono, raw_l, std::nullopt, false), 0.05);
  const Rectifier stereo(raw_l, raw_r);
  expectStereoContract(stereo, raw_l, raw_r);
  EXPECT_LT(worstMapError(stereo, raw_l, raw_r, false), 0.05);
  EXPECT_LT(worstMapError(stereo, raw_l, raw_r, true), 0.05);
}

TEST(RectifierTest, RectifiedKittiPairPassesThrough) {
  const CameraModel raw_l = kittiCam0(), raw_r = kittiCam1();
  const Rectifier rect(raw_l, raw_r);
  EXPECT_TRUE(rect.isIdentity());
  EXPECT_NEAR(rect.baselineM(), 0.537, 1e-12);
  EXPECT_DOUBLE_EQ(rect.left().fx, raw_l.fx);
  EXPECT_DOUBLE_EQ(rect.right()->cx, raw_r.cx);
  EXPECT_TRUE(rect.left().T_b_c.isApprox(raw_l.T_b_c, 1e-12));
  EXPECT_TRUE(rect.right()->T_b_c.isApprox(raw_r.T_b_c, 1e-12));
  const cv::Mat left(376, 1241, CV_8U, cv::Scalar(1)), right(376, 1241, CV_8U, cv::Scalar(2));
  const RectifiedImages out = rect.rectify(left, right);
  EXPECT_EQ(out.left.data, left.data);  // no copy, no remap
  EXPECT_EQ(out.right.data, right.data);
}

// KITTI calibration files print rotations to 7 digits: the IMU chain gives both cameras the same
// slightly non-orthonormal rotation. Still a rectified pair, and the models come out exact.
TEST(RectifierTest, RoundedCalibrationRotationStillPassesThrough) {
  CameraModel raw_l = kittiCam0();
  Eigen::Matrix3d rounded = raw_l.T_b_c.linear();
  rounded(0, 1) += 3e-7;
  rounded(2, 0) -= 2e-7;
  raw_l.T_b_c.linear() = rounded;
  CameraModel raw_r = raw_l;
  raw_r.name = "image_01";
  raw_r.T_b_c.translation() += 0.537 * rounded.col(0);
  const Rectifier rect(raw_l, raw_r);
  EXPECT_TRUE(rect.isIdentity());
  EXPECT_NEAR(rect.baselineM(), 0.537, 1e-6);
  const Eigen::Matrix3d& R = rect.left().T_b_c.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_LT((R - rounded).norm(), 1e-6);
  const Eigen::Isometry3d T_l_r = rect.left().T_b_c.inverse() * rect.right()->T_b_c;
  EXPECT_LT((T_l_r.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_LT((T_l_r.translation() - Eigen::Vector3d(rect.baselineM(), 0, 0)).norm(), 1e-14);
}

TEST(RectifierTest, UndistortedMonoAndZeroDistortionAreIdentity) {
  EXPECT_TRUE(Rectifier(kittiCam0()).isIdentity());
  CameraModel zeros = kittiCam0();
  zeros.distortion = {0, 0, 0, 0, 0};
  const Rectifier rect(zeros);
  EXPECT_TRUE(rect.isIdentity());
  EXPECT_TRUE(rect.left().distortion.empty());
  // Rotated by more than the tolerance: a real rectification, though nothing is distorted.
  CameraModel turned = kittiCam1();
  turned.T_b_c.rotate(Eigen::AngleAxisd(1e-3, Eigen::Vector3d::UnitY()));
  const Rectifier rect2(kittiCam0(), turned);
  EXPECT_FALSE(rect2.isIdentity());
  EXPECT_LT(worstMapError(rect2, kittiCam0(), turned, true), 0.05);
}

TEST(RectifierTest, RefusesInvalidCamerasAndRigs) {
  EXPECT_THAT(rectifierError(kittiCam1(), kittiCam0()), HasSubstr("right of the left"));
  EXPECT_THAT(rectifierError(eurocCam1(), eurocCam0()), HasSubstr("side by side"));
  CameraModel above = kittiCam0();  // a vertical rig
  above.T_b_c = above.T_b_c * Eigen::Translation3d(0.01, -0.5, 0.0);
  EXPECT_THAT(rectifierError(kittiCam0(), above), HasSubstr("side by side"));
  CameraModel small = kittiCam1();
  small.width_px = 640;
  EXPECT_THAT(rectifierError(kittiCam0(), small), HasSubstr("different image sizes"));
  CameraModel three = kittiCam0();
  three.distortion = {0.1, 0.01, 0.0};
  EXPECT_THAT(rectifierError(three, std::nullopt), HasSubstr("distortion coefficients"));
  CameraModel no_focal = kittiCam0();
  no_focal.fx = 0.0;
  EXPECT_THAT(rectifierError(no_focal, std::nullopt), HasSubstr("focal lengths"));

  const Rectifier rect(eurocCam0(), eurocCam1());
  const cv::Mat wrong(480, 640, CV_8U), ok(480, 752, CV_8U);
  EXPECT_THROW((void)rect.rectify(wrong, ok), InvalidInput);
  EXPECT_THROW((void)rect.rectify(ok), InvalidInput);  // stereo needs both images
}

}  // namespace
}  // namespace gvio::odometry
