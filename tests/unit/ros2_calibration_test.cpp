// The calibration a ROS 2 bag carries (issue 60): intrinsics and distortion from CameraInfo,
// extrinsics from /tf_static, the stereo baseline from the CameraInfos' P when the tree lacks the
// second camera, the GNSS lever arm, and the defects that must not pass silently.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.hpp"
#include "io/ros2/ros2_bag_writer.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros2_dataset.hpp"
#include "support/fixtures.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

constexpr std::uint32_t kWidth = 16, kHeight = 12;

struct BagSpec {
  bool camera_info = true;
  bool cam1_link = true;   // imu -> cam1 on /tf_static
  bool rectified = false;  // image_rect topics
  std::uint32_t info_width = kWidth;
  std::string distortion_model = "plumb_bob";
  std::vector<double> d = {0.1, -0.05, 0.001, 0.002, 0.0};
};

Eigen::Isometry3d pose(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

const Eigen::Isometry3d kImuCam0 = pose({1, 2, 3}, 1.9, {0.1, -0.2, 0.05});
const Eigen::Isometry3d kCam0Cam1 = pose({0, 1, 0}, 0.0, {0.12, 0.0, 0.0});

TransformMessage link(const std::string& child, const Eigen::Isometry3d& T) {
  TransformMessage m;
  m.frame_id = "imu";
  m.child_frame_id = child;
  const Eigen::Quaterniond q(T.rotation());
  m.rotation_xyzw = {q.x(), q.y(), q.z(), q.w()};
  m.translation = {T.translation().x(), T.translation().y(), T.translation().z()};
  return m;
}

CameraInfoMessage info(const BagSpec& spec, int camera) {
  CameraInfoMessage m;
  m.frame_id = "cam" + std::to_string(camera) + "_optical";
  m.width = spec.info_width;
  m.height = kHeight;
  m.distortion_model = spec.distortion_model;
  m.d = spec.d;
  m.k = {20.0, 0.0, 8.0, 0.0, 21.0, 6.0, 0.0, 0.0, 1.0};
  m.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double tx = camera == 1 ? -19.0 * kCam0Cam1.translation().x() : 0.0;
  m.p = {19.0, 0.0, 7.5, tx, 0.0, 19.0, 6.5, 0.0, 0.0, 0.0, 1.0, 0.0};
  return m;
}

fs::path writeBag(const fs::path& folder, const BagSpec& spec) {
  fs::create_directories(folder);
  Ros2BagWriter w(folder, "rig", Ros2Storage::kMcap, "none");
  const std::string image_name = spec.rectified ? "image_rect" : "image_raw";
  const std::size_t cam[2] = {w.addTopic("/stereo/left/" + image_name, kRos2ImageType),
                              w.addTopic("/stereo/right/" + image_name, kRos2ImageType)};
  const std::size_t infos[2] = {w.addTopic("/stereo/left/camera_info", kRos2CameraInfoType),
                                w.addTopic("/stereo/right/camera_info", kRos2CameraInfoType)};
  const std::size_t imu = w.addTopic("/imu/data", kRos2ImuType);
  const std::size_t gnss = w.addTopic("/fix", kRos2NavSatFixType);
  const std::size_t tf = w.addTopic("/tf_static", kRos2TfType);
  std::vector<TransformMessage> links = {link("cam0_optical", kImuCam0),
                                         link("antenna", pose({0, 0, 1}, 0.0, {0.3, 0.0, 1.1}))};
  if (spec.cam1_link) links.push_back(link("cam1_optical", kImuCam0 * kCam0Cam1));
  w.write(tf, 1'000'000'000, encodeTfMessage(links));
  for (int k = 0; k < 3; ++k) {
    const std::int64_t t = 1'000'000'000 + k * 100'000'000LL;
    for (int c = 0; c < 2; ++c) {
      Ros2Image image;
      image.image.t.header_ns = t;
      image.image.encoding = "mono8";
      image.image.width = kWidth;
      image.image.height = kHeight;
      image.image.step = kWidth;
      image.image.data.assign(kWidth * kHeight, static_cast<std::uint8_t>(40 * k + c));
      image.frame_id = "cam" + std::to_string(c) + "_optical";
      w.write(cam[c], t, encodeImage(image));
      if (spec.camera_info) {
        CameraInfoMessage m = info(spec, c);
        m.t.header_ns = t;
        w.write(infos[c], t, encodeCameraInfo(m));
      }
    }
    Ros2Imu m;
    m.imu.t.header_ns = t;
    m.frame_id = "imu";
    w.write(imu, t, encodeImu(m));
    Ros2NavSatFix f;
    f.fix.t.header_ns = t;
    f.fix.status = 0;
    f.fix.lat_deg = 35.0;
    f.fix.lon_deg = 137.0;
    f.frame_id = "antenna";
    w.write(gnss, t, encodeNavSatFix(f));
  }
  w.close();
  return folder;
}

double maxDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

TEST(Ros2Calibration, CameraInfoAndTfStaticCalibrateTheRig) {
  test::TempDir dir("ros2_calib");
  const Dataset ds = readRos2Bag(writeBag(dir.path() / "bag", {}), ReaderConfig{});
  ASSERT_EQ(ds.cameras.size(), 2U);
  EXPECT_TRUE(ds.calibration_missing.empty()) << ds.calibration_missing;
  const CameraModel& c0 = ds.cameras[0];
  EXPECT_EQ(c0.fx, 20.0);
  EXPECT_EQ(c0.fy, 21.0);
  EXPECT_EQ(c0.cx, 8.0);
  EXPECT_EQ(c0.cy, 6.0);
  EXPECT_EQ(c0.distortion, (std::vector<double>{0.1, -0.05, 0.001, 0.002, 0.0}));
  EXPECT_LT(maxDifference(c0.T_b_c, kImuCam0), 1e-12);
  EXPECT_LT(maxDifference(ds.cameras[1].T_b_c, kImuCam0 * kCam0Cam1), 1e-12);
  ASSERT_TRUE(ds.gnss_lever_arm_b);
  EXPECT_LT((*ds.gnss_lever_arm_b - Eigen::Vector3d(0.3, 0.0, 1.1)).norm(), 1e-12);
  std::string sources;
  for (const CalibrationSource& s : ds.calibration_sources)
    sources += s.value + ": " + s.source + "\n";
  EXPECT_THAT(sources, HasSubstr("cam0 intrinsics: /stereo/left/camera_info (plumb_bob"));
  EXPECT_THAT(sources, HasSubstr("T_b_cam1: /tf_static: imu -> cam1_optical"));
  EXPECT_THAT(sources, HasSubstr("GNSS lever arm: /tf_static: imu -> antenna"));
}

TEST(Ros2Calibration, TheSecondCameraFromTheProjectionsWhenTheTreeLacksIt) {
  test::TempDir dir("ros2_calib_p");
  BagSpec spec;
  spec.cam1_link = false;
  const Dataset ds = readRos2Bag(writeBag(dir.path() / "bag", spec), ReaderConfig{});
  ASSERT_TRUE(ds.calibration_missing.empty()) << ds.calibration_missing;
  EXPECT_LT(maxDifference(ds.cameras[1].T_b_c, kImuCam0 * kCam0Cam1), 1e-12);
  EXPECT_EQ(ds.calibration_sources[3].value, "T_cam0_cam1");
}

TEST(Ros2Calibration, RectifiedTopicsTakeTheProjection) {
  test::TempDir dir("ros2_calib_rect");
  BagSpec spec;
  spec.rectified = true;
  const Dataset ds = readRos2Bag(writeBag(dir.path() / "bag", spec), ReaderConfig{});
  EXPECT_EQ(ds.cameras[0].fx, 19.0);
  EXPECT_EQ(ds.cameras[0].cx, 7.5);
  EXPECT_TRUE(ds.cameras[0].distortion.empty());
}

TEST(Ros2Calibration, WhatTheBagLacksOrContradictsIsSaid) {
  test::TempDir dir("ros2_calib_bad");
  BagSpec none;
  none.camera_info = false;
  const Dataset missing = readRos2Bag(writeBag(dir.path() / "none", none), ReaderConfig{});
  EXPECT_EQ(missing.cameras[0].fx, 0.0);
  EXPECT_THAT(missing.calibration_missing, HasSubstr("no CameraInfo on /stereo/left/camera_info"));

  // A CameraInfo that contradicts its images, or names a model gvio cannot use: uncalibrated,
  // with the reason (Kalibr files can still calibrate the cameras).
  BagSpec wide;
  wide.info_width = 640;
  const Dataset contradicted = readRos2Bag(writeBag(dir.path() / "wide", wide), ReaderConfig{});
  EXPECT_EQ(contradicted.cameras[0].fx, 0.0);
  EXPECT_THAT(contradicted.calibration_missing,
              HasSubstr("/stereo/left/camera_info is for 640x12 pixels, the images are 16x12"));
  BagSpec odd;
  odd.distortion_model = "kannala_brandt";
  EXPECT_THAT(readRos2Bag(writeBag(dir.path() / "odd", odd), ReaderConfig{}).calibration_missing,
              HasSubstr("'kannala_brandt'"));
  BagSpec rational;
  rational.distortion_model = "rational_polynomial";
  rational.d = {0.1, -0.05, 0.001, 0.002, 0.01, 0.02, -0.01, 0.003};
  const Dataset eight = readRos2Bag(writeBag(dir.path() / "eight", rational), ReaderConfig{});
  EXPECT_EQ(eight.cameras[0].distortion.size(), 8U);
}

}  // namespace
}  // namespace gvio::io::ros2
