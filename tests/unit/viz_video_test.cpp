// The pieces of `gvio render --video` (viz/video_views.hpp) and render::lookAtCamera.
#include <gtest/gtest.h>

#include "odometry/error.hpp"
#include "render/camera.hpp"
#include "render/render_error.hpp"
#include "viz/video_views.hpp"

namespace gvio::viz {
namespace {

Trajectory straightDrive(int poses, double step_s) {
  Trajectory t;
  for (int i = 0; i < poses; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(2.0 * i, 0.0, 0.0);
    t.poses.push_back(T);
    t.t_ns.push_back(1'000'000'000LL + static_cast<std::int64_t>(i * step_s * 1e9));
  }
  return t;
}

TEST(LookAtCamera, TheTargetIsAtTheImageCentreAndUpIsUp) {
  const Eigen::Vector3d eye(3, -4, 10), target(20, 5, 1);
  const render::RenderCamera c = render::lookAtCamera(eye, target, 640, 480, 50.0, 0.5, 500.0);
  double z = 0.0;
  const Eigen::Vector2d px = render::projectToPixel(c, target, &z);
  EXPECT_NEAR(px.x(), 319.5, 1e-9);
  EXPECT_NEAR(px.y(), 239.5, 1e-9);
  EXPECT_NEAR(z, (target - eye).norm(), 1e-9);
  // A point above the target is higher in the image (smaller y).
  EXPECT_LT(render::projectToPixel(c, target + Eigen::Vector3d(0, 0, 1)).y(), px.y());
  EXPECT_THROW((void)render::lookAtCamera(eye, eye, 640, 480, 50.0, 0.5, 500.0),
               render::RenderError);
}

TEST(VideoFrameTimes, OneFramePerStepFromTheFirstStampToTheLast) {
  const Trajectory t = straightDrive(101, 0.1);  // 10 s
  const auto real_time = videoFrameTimes(t, 10.0, 1.0);
  ASSERT_EQ(real_time.size(), 101U);
  EXPECT_EQ(real_time.front(), t.t_ns.front());
  EXPECT_EQ(real_time.back(), t.t_ns.back());
  EXPECT_EQ(videoFrameTimes(t, 10.0, 4.0).size(), 26U);  // every 0.4 s
  EXPECT_THROW((void)videoFrameTimes(t, 0.0, 1.0), InvalidInput);
  EXPECT_THROW((void)videoFrameTimes(t, 10.0, -1.0), InvalidInput);
  EXPECT_THROW((void)videoFrameTimes(Trajectory{}, 10.0, 1.0), InvalidInput);
  // A span: 2 s to 4 s, both ends included; a span past the end is clamped to it.
  const auto span = videoFrameTimes(t, 10.0, 1.0, {2.0, 4.0});
  ASSERT_EQ(span.size(), 21U);
  EXPECT_EQ(span.front(), t.t_ns[20]);
  EXPECT_EQ(span.back(), t.t_ns[40]);
  EXPECT_EQ(videoFrameTimes(t, 10.0, 1.0, {9.0, 60.0}).back(), t.t_ns.back());
  EXPECT_THROW((void)videoFrameTimes(t, 10.0, 1.0, {4.0, 2.0}), InvalidInput);
  EXPECT_THROW((void)videoFrameTimes(t, 10.0, 1.0, {11.0, 20.0}), InvalidInput);
  EXPECT_THROW((void)videoFrameTimes(t, 10.0, 1.0, {-1.0, 2.0}), InvalidInput);
}

TEST(VideoViews, ChaseCameraLooksAlongTheHeadingFromBehind) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // north
  T.translation() = Eigen::Vector3d(5, 5, 1);
  const render::RenderCamera c = chaseCamera(T, 320, 240);
  const Eigen::Isometry3d T_w_c(c.view.inverse());
  EXPECT_LT(T_w_c.translation().y(), 5.0 - 10.0);  // behind (south of) the body
  EXPECT_GT(T_w_c.translation().z(), 1.0 + 5.0);   // above it
  double z = 0.0;
  const Eigen::Vector2d px = render::projectToPixel(c, T.translation(), &z);
  EXPECT_GT(z, 0.0);
  EXPECT_NEAR(px.x(), 159.5, 1.0);  // straight ahead, below the image centre
  EXPECT_GT(px.y(), 119.5);
}

TEST(VideoViews, PathUntilAndPoseAtFollowTheStamps) {
  const Trajectory t = straightDrive(11, 1.0);
  EXPECT_EQ(pathUntil(t, t.t_ns[4]).size(), 5U);
  EXPECT_EQ(pathUntil(t, t.t_ns[0] - 1).size(), 0U);
  // Poses 1 s apart are a gap (interpolatePose bridges 0.5 s at most): the last pose before.
  EXPECT_NEAR(poseAt(t, t.t_ns[2] + 500'000'000LL).translation().x(), 4.0, 1e-9);
  const Trajectory dense = straightDrive(11, 0.1);
  EXPECT_NEAR(poseAt(dense, dense.t_ns[2] + 50'000'000LL).translation().x(), 5.0, 1e-9);
}

TEST(VideoViews, TheMapIsRevealedOnlyNearThePathDriven) {
  const Eigen::AlignedBox3d box(Eigen::Vector3d(0, -50, 0), Eigen::Vector3d(100, 50, 1));
  const render::RenderCamera c = render::topDownCamera(box, 200, 200, 0.0);
  render::ImageRgba full;
  full.width = full.height = 200;
  full.rgba.assign(200 * 200 * 4, 0);  // all black: the "map"
  const std::vector<Eigen::Vector3d> path = {{0, 0, 0}, {10, 0, 0}};
  const render::ImageRgba shown = revealedAlongPath(full, c, path, 5.0);
  const auto at = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = render::projectToPixel(c, p);
    return shown.pixel(static_cast<int>(px.x()), static_cast<int>(px.y()))[0];
  };
  EXPECT_EQ(at({10, 2, 0}), 0);    // within 5 m of the path: the map
  EXPECT_EQ(at({60, 0, 0}), 255);  // far ahead: not yet
  EXPECT_EQ(at({10, 20, 0}), 255);
}

}  // namespace
}  // namespace gvio::viz
