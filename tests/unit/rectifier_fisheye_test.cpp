// odometry::Rectifier on equidistant (fisheye, Kannala-Brandt) cameras: the TUM VI stereo rig
// (~190 deg lenses, ~2.7 deg between the cameras) rectified with cv::fisheye. Rows align, the
// rectified images sample the raw ones exactly where the raw fisheye models project a point, no
// rectified pixel looks outside the raw image, and cameras that cannot be rectified together are
// refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "odometry/rectifier.hpp"
#include "support/euroc_camera.hpp"
#include "support/rectification_check.hpp"
#include "support/tumvi_camera.hpp"

namespace gvio::odometry {
namespace {
using test::expectStereoContract;
using test::projectPinhole;
using test::projectRaw;
using test::rectifierError;
using test::tumviCam0;
using test::tumviCam1;
using test::visiblePoints;
using test::worstMapError;
using testing::AllOf;
using testing::HasSubstr;

// Kannala-Brandt (2006) as Kalibr's equidistant model writes it: theta = atan(r) of the pinhole
// point, r_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8), scaled along r.
Eigen::Vector2d kannalaBrandt(const CameraModel& cam, const Eigen::Vector3d& p_c) {
  const double x = p_c.x() / p_c.z(), y = p_c.y() / p_c.z(), r = std::hypot(x, y);
  const double theta = std::atan(r), t2 = theta * theta;
  const std::vector<double>& k = cam.distortion;
  const double r_d = theta * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  return {cam.fx * r_d / r * x + cam.cx, cam.fy * r_d / r * y + cam.cy};
}

// The largest distance (px) by which a rectified pixel on the image border samples outside the
// raw image [0, w-1] x [0, h-1]: each border pixel's ray through the raw model (0 when all fall
// inside).
double worstBorderOvershoot(const CameraModel& rectified, const CameraModel& raw) {
  double worst = 0.0;
  const auto check = [&](double u, double v) {
    const Eigen::Vector3d ray((u - rectified.cx) / rectified.fx, (v - rectified.cy) / rectified.fy,
                              1.0);
    const Eigen::Vector2d px = projectRaw(raw, rectified.T_b_c * (10.0 * ray));
    const double w = raw.width_px - 1.0, h = raw.height_px - 1.0;
    worst = std::max({worst, -px.x(), -px.y(), px.x() - w, px.y() - h});
  };
  for (int u = 0; u < rectified.width_px; ++u) {
    check(u, 0);
    check(u, rectified.height_px - 1);
  }
  for (int v = 0; v < rectified.height_px; ++v) {
    check(0, v);
    check(rectified.width_px - 1, v);
  }
  return worst;
}

// The test's projection helper follows Kalibr's coefficient order: cv::fisheye's k1..k4 are
// Kannala-Brandt's, so a Kalibr equidistant calibration goes to OpenCV unchanged.
TEST(RectifierFisheyeTest, OpenCvFisheyeIsKannalaBrandtInKalibrsOrder) {
  const CameraModel cam = tumviCam0();
  for (const Eigen::Vector3d& p_c :
       {Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector3d(2.5, 1.5, 1.0),
        Eigen::Vector3d(-4.0, 3.0, 0.5)}) {
    const Eigen::Vector2d expected = kannalaBrandt(cam, p_c);
    EXPECT_LT((projectRaw(cam, cam.T_b_c * p_c) - expected).norm(), 1e-9) << p_c.transpose();
  }
  // The last point lies 84 deg off the axis, where tan(theta) is ~7 times theta: a pinhole model
  // would put it far outside the 512 px image, the fisheye model well inside.
  EXPECT_TRUE(test::inside(cam, kannalaBrandt(cam, {-4.0, 3.0, 0.5}), 0));
}

TEST(RectifierFisheyeTest, StereoRigGetsOneKAndRowAlignedCameras) {
  const CameraModel raw_l = tumviCam0(), raw_r = tumviCam1();
  const Rectifier rect(raw_l, raw_r);
  EXPECT_FALSE(rect.isIdentity());
  ASSERT_TRUE(rect.isStereo());
  expectStereoContract(rect, raw_l, raw_r);
  const CameraModel& l = rect.left();
  const CameraModel& r = *rect.right();
  for (const CameraModel* cam : {&l, &r}) {
    EXPECT_EQ(cam->distortion_model, Distortion::kRadtan);  // a pinhole
    EXPECT_EQ(cam->width_px, 512);
    EXPECT_EQ(cam->height_px, 512);
  }
  EXPECT_EQ(r.name, "cam1");
  // Rectification turns the cameras about their centres, by about half the 2.7 deg between them
  // each, not by a quarter turn onto some other axis.
  EXPECT_LT(Eigen::AngleAxisd(raw_l.T_b_c.linear().transpose() * l.T_b_c.linear()).angle(),
            3.0 * M_PI / 180.0);
  EXPECT_LT(Eigen::AngleAxisd(raw_r.T_b_c.linear().transpose() * r.T_b_c.linear()).angle(),
            3.0 * M_PI / 180.0);
  EXPECT_NEAR(rect.baselineM(), 0.1011, 1e-3);
  // Disparity f b / z.
  for (const Eigen::Vector3d& p_b : visiblePoints(rect, raw_l, raw_r)) {
    const Eigen::Vector2d pl = projectPinhole(l, p_b), pr = projectPinhole(r, p_b);
    const double z_m = (l.T_b_c.inverse() * p_b).z();
    EXPECT_NEAR(pl.x() - pr.x(), l.fx * rect.baselineM() / z_m, 1e-6);
  }
}

// The rectified models and the rectified images agree: a point projected by a rectified pinhole
// model lands on the pixel that was resampled from where the raw fisheye model projects it.
TEST(RectifierFisheyeTest, StereoMapsSampleWhereRawFisheyeModelsProject) {
  const CameraModel raw_l = tumviCam0(), raw_r = tumviCam1();
  const Rectifier rect(raw_l, raw_r);
  EXPECT_LT(worstMapError(rect, raw_l, raw_r, false), 0.05);
  EXPECT_LT(worstMapError(rect, raw_l, raw_r, true), 0.05);
  // The rectified views stay inside the raw images (no black border for the tracker), and only
  // just: 1 % wider, and one of them would look outside. (cv::fisheye::stereoRectify with balance
  // 0 alone, f = 61.75 px here, samples up to 4.6 px outside the left image, 3.4 px the right.)
  EXPECT_LT(worstBorderOvershoot(rect.left(), raw_l), 1e-6);
  EXPECT_LT(worstBorderOvershoot(*rect.right(), raw_r), 1e-6);
  CameraModel wider_l = rect.left(), wider_r = *rect.right();
  for (CameraModel* cam : {&wider_l, &wider_r}) {
    cam->fx *= 0.99;
    cam->fy *= 0.99;
  }
  EXPECT_GT(std::max(worstBorderOvershoot(wider_l, raw_l), worstBorderOvershoot(wider_r, raw_r)),
            0.1);
}

TEST(RectifierFisheyeTest, MonoCameraIsUndistorted) {
  const CameraModel raw = tumviCam0();
  const Rectifier rect(raw);
  EXPECT_FALSE(rect.isIdentity());
  EXPECT_FALSE(rect.isStereo());
  EXPECT_TRUE(rect.left().distortion.empty());
  EXPECT_EQ(rect.left().distortion_model, Distortion::kRadtan);
  EXPECT_TRUE(rect.left().T_b_c.isApprox(raw.T_b_c, 1e-15));
  EXPECT_LT(worstMapError(rect, raw, std::nullopt, false), 0.05);
  EXPECT_LT(worstBorderOvershoot(rect.left(), raw), 1e-6);
  CameraModel wider = rect.left();
  wider.fx *= 0.99;
  wider.fy *= 0.99;
  EXPECT_GT(worstBorderOvershoot(wider, raw), 0.1);
  const cv::Mat grey(raw.height_px, raw.width_px, CV_8U, cv::Scalar(200));
  const RectifiedImages out = rect.rectify(grey);
  EXPECT_EQ(out.left.type(), CV_8U);
  EXPECT_EQ(out.left.size(), grey.size());
  EXPECT_TRUE(out.right.empty());
}

// Kannala-Brandt with k1..k4 = 0 images the ray's angle (r_d = theta), not its tangent: still a
// fisheye to undistort, never a pinhole to pass through.
TEST(RectifierFisheyeTest, ZeroCoefficientsAreStillAFisheye) {
  CameraModel raw_l = tumviCam0();
  raw_l.distortion = {0, 0, 0, 0};
  const Rectifier mono(raw_l);
  EXPECT_FALSE(mono.isIdentity());
  EXPECT_LT(worstMapError(mono, raw_l, std::nullopt, false), 0.05);
  // A pair that would pass through as pinholes: one K, one rotation, offset along x.
  CameraModel raw_r = raw_l;
  raw_r.name = "cam1";
  raw_r.T_b_c = raw_l.T_b_c * Eigen::Translation3d(0.1, 0.0, 0.0);
  const Rectifier stereo(raw_l, raw_r);
  EXPECT_FALSE(stereo.isIdentity());
  EXPECT_NEAR(stereo.baselineM(), 0.1, 1e-12);
  EXPECT_LT(worstMapError(stereo, raw_l, raw_r, true), 0.05);
}

TEST(RectifierFisheyeTest, RefusesBadCoefficientsMixedModelsAndUprightRigs) {
  CameraModel five = tumviCam0();
  five.distortion.push_back(0.001);
  EXPECT_THAT(rectifierError(five, std::nullopt),
              AllOf(HasSubstr("camera cam0"), HasSubstr("equidistant"),
                    HasSubstr("exactly 4 distortion coefficients"), HasSubstr("got 5")));
  CameraModel none = tumviCam0();
  none.distortion.clear();
  EXPECT_THAT(rectifierError(none, std::nullopt), HasSubstr("got 0"));
  CameraModel bad_right = tumviCam1();
  bad_right.distortion.resize(3);
  EXPECT_THAT(rectifierError(tumviCam0(), bad_right),
              AllOf(HasSubstr("camera cam1"), HasSubstr("got 3")));

  // One model per pair: a radtan camera beside a fisheye one, either side, even a pinhole.
  CameraModel radtan_right = test::eurocCam1();
  radtan_right.width_px = radtan_right.height_px = 512;
  EXPECT_THAT(rectifierError(tumviCam0(), radtan_right),
              AllOf(HasSubstr("camera cam0 is equidistant and camera cam1 radtan"),
                    HasSubstr("different distortion models")));
  CameraModel pinhole_left = tumviCam0();
  pinhole_left.distortion_model = Distortion::kRadtan;
  pinhole_left.distortion.clear();
  EXPECT_THAT(rectifierError(pinhole_left, tumviCam1()),
              HasSubstr("camera cam0 is radtan and camera cam1 equidistant"));

  // Swapped sides, and a rig with the second camera above the first: cv::fisheye::stereoRectify
  // would turn either onto x (a half or a quarter turn) rather than refuse it.
  EXPECT_THAT(rectifierError(tumviCam1(), tumviCam0()), HasSubstr("side by side"));
  CameraModel above = tumviCam0();
  above.name = "cam1";
  above.T_b_c = above.T_b_c * Eigen::Translation3d(0.01, -0.1, 0.0);
  EXPECT_THAT(rectifierError(tumviCam0(), above), HasSubstr("side by side"));
  EXPECT_EQ(rectifierError(tumviCam0(), tumviCam1()), "");
}

}  // namespace
}  // namespace gvio::odometry
