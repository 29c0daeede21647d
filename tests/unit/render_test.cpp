// render/ on whatever EGL offers (llvmpipe in CI): context, exact pinhole camera, readback,
// primitives, a golden image and many frames from one context.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "render/render_error.hpp"
#include "render/renderer.hpp"
#include "sim/kitti_convention.hpp"
#include "support/fixtures.hpp"
#include "support/render_fixture.hpp"

namespace gvio::render {
namespace {

class RenderTest : public test::SharedRendererTest {};

// KITTI's rectified camera: the simulator's.
PinholeIntrinsics kittiCamera() {
  return sim::kittiIntrinsics();
}

Eigen::Isometry3d someCameraPose() {
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  T_w_c.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  T_w_c.translation() = Eigen::Vector3d(120.0, -45.0, 3.0);
  return T_w_c;
}

std::vector<cv::Point2d> opencvProject(const std::vector<Eigen::Vector3d>& p_w,
                                       const PinholeIntrinsics& K, const Eigen::Isometry3d& T_w_c) {
  const Eigen::Isometry3d T_c_w = T_w_c.inverse();
  cv::Mat R, rvec,
      tvec = (cv::Mat_<double>(3, 1) << T_c_w.translation().x(), T_c_w.translation().y(),
              T_c_w.translation().z());
  cv::Mat Rm(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) Rm.at<double>(r, c) = T_c_w.linear()(r, c);
  }
  cv::Rodrigues(Rm, rvec);
  const cv::Mat camera = (cv::Mat_<double>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  std::vector<cv::Point3d> obj;
  for (const auto& p : p_w) obj.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, rvec, tvec, camera, cv::Mat(), img);
  return img;
}

TEST_F(RenderTest, ContextReportsPathAndRenderer) {
  const auto& info = context_->info();
  EXPECT_FALSE(info.platform.empty());
  EXPECT_FALSE(info.gl_renderer.empty());
  EXPECT_THAT(info.gl_version, testing::Not(testing::IsEmpty()));
  std::cout << "[ context ] " << info.platform << " | " << info.gl_version << " | "
            << info.gl_renderer << "\n";
}

TEST_F(RenderTest, PinholeMathMatchesOpenCv) {
  const PinholeIntrinsics K = kittiCamera();
  const Eigen::Isometry3d T_w_c = someCameraPose();
  const RenderCamera cam = pinholeCamera(K, T_w_c);
  std::vector<Eigen::Vector3d> pts;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i)
    pts.push_back(T_w_c * Eigen::Vector3d{8 * u(rng), 2 * u(rng), 20 + 15 * u(rng)});
  const auto cv_px = opencvProject(pts, K, T_w_c);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d px = projectToPixel(cam, pts[i]);
    EXPECT_NEAR(px.x(), cv_px[i].x, 1e-6);
    EXPECT_NEAR(px.y(), cv_px[i].y, 1e-6);
  }
}

// A textured checkerboard seen by the exact pinhole camera: OpenCV's sub-pixel corner detector
// must find every inner corner where cv::projectPoints puts the board's 3-D corners.
TEST_F(RenderTest, TexturedBoardCornersLandWhereOpenCvProjects) {
  constexpr int kCols = 10, kRows = 7, kTexel = 32;  // squares; 9 x 6 inner corners
  constexpr double kSquare = 0.4;                    // metres
  Texture board{kCols * kTexel, kRows * kTexel, 1, {}};
  for (int y = 0; y < board.height; ++y) {
    for (int x = 0; x < board.width; ++x)
      board.data.push_back(((x / kTexel + y / kTexel) % 2) ? 230 : 25);
  }
  // Board in its own frame (x right, y down, z = 0), placed 9 m in front of the camera, tilted.
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  T_w_b.linear() = (Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  const Eigen::Isometry3d T_w_c = someCameraPose();
  T_w_b.translation() = T_w_c * Eigen::Vector3d(-2.0, -1.2, 9.0);
  T_w_b.linear() = T_w_c.linear() * T_w_b.linear();
  Scene scene;
  scene.textures.push_back(board);
  TexturedMesh quad;
  const double w = kCols * kSquare, h = kRows * kSquare;
  quad.vertices = {T_w_b * Eigen::Vector3d(0, 0, 0), T_w_b * Eigen::Vector3d(w, 0, 0),
                   T_w_b * Eigen::Vector3d(w, h, 0), T_w_b * Eigen::Vector3d(0, h, 0)};
  quad.uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // texture row 0 at the board's y = 0
  quad.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(quad);
  const PinholeIntrinsics K = kittiCamera();
  const GpuScene gpu(scene);
  Framebuffer fb(K.width, K.height);
  const ImageRgba img = renderer_->renderColor(gpu, pinholeCamera(K, T_w_c), fb);
  cv::Mat rgba(img.height, img.width, CV_8UC4, const_cast<std::uint8_t*>(img.rgba.data())), grey;
  cv::cvtColor(rgba, grey, cv::COLOR_RGBA2GRAY);
  std::vector<cv::Point2f> found;
  if (std::getenv("GVIO_RENDER_DEBUG") != nullptr) cv::imwrite("/tmp/board.png", grey);
  ASSERT_TRUE(cv::findChessboardCorners(grey, cv::Size(kCols - 1, kRows - 1), found));
  cv::cornerSubPix(grey, found, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  std::vector<Eigen::Vector3d> corners;
  for (int r = 1; r < kRows; ++r) {
    for (int c = 1; c < kCols; ++c)
      corners.push_back(T_w_b * Eigen::Vector3d(c * kSquare, r * kSquare, 0));
  }
  const auto expected = opencvProject(corners, K, T_w_c);
  double worst = 0.0;
  Eigen::Vector2d mean_offset = Eigen::Vector2d::Zero();
  for (const auto& e : expected) {  // detection order may be reversed: match each to the nearest
    Eigen::Vector2d best(1e9, 1e9);
    for (const auto& f : found) {
      const Eigen::Vector2d d(static_cast<double>(f.x) - e.x, static_cast<double>(f.y) - e.y);
      if (d.norm() < best.norm()) best = d;
    }
    worst = std::max(worst, best.norm());
    mean_offset += best / static_cast<double>(expected.size());
  }
  std::cout << "[ pinhole ] " << expected.size() << " corners: worst error " << worst
            << " px, mean offset (" << mean_offset.x() << ", " << mean_offset.y() << ") px\n";
  // A systematic offset would be a camera-model error; the spread is the detector's.
  EXPECT_LT(mean_offset.norm(), 0.05);
  EXPECT_LT(worst, 0.25);
}

// A textured wall filling the view at a known distance: colour and metric depth read back.
TEST_F(RenderTest, ColourAndDepthReadback) {
  Scene scene;
  scene.background = Color(0, 0, 1, 1);
  scene.textures.push_back(Texture{2, 2, 1, {200, 200, 200, 200}});
  TexturedMesh wall;
  const double z = 12.5;
  wall.vertices = {{-50, -50, z}, {50, -50, z}, {50, 50, z}, {-50, 50, z}};
  wall.uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  wall.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(wall);
  const GpuScene gpu(scene);
  PinholeIntrinsics K = kittiCamera();
  K.width = 160;
  K.height = 120;
  K.cx = 79.5;
  K.cy = 59.5;
  const RenderCamera cam = pinholeCamera(K, Eigen::Isometry3d::Identity());
  Framebuffer fb(K.width, K.height);
  const ImageRgba img = renderer_->renderColor(gpu, cam, fb);
  EXPECT_EQ(img.pixel(10, 10)[0], 200);
  EXPECT_EQ(img.pixel(150, 110)[1], 200);
  const DepthImage depth = renderer_->renderDepth(gpu, cam, fb);
  EXPECT_NEAR(depth.at(80, 60), z, 1e-3 * z);
  EXPECT_NEAR(depth.at(0, 0), z, 1e-3 * z);
  // Exposure gain scales the texture.
  DrawOptions half;
  half.exposure_gain = 0.5F;
  EXPECT_NEAR(renderer_->renderColor(gpu, cam, fb, half).pixel(80, 60)[0], 100, 1);
  // Nothing drawn -> background colour and depth 0.
  const GpuScene empty(Scene{});
  EXPECT_EQ(renderer_->renderColor(empty, cam, fb).pixel(5, 5)[2], 255);
  EXPECT_EQ(renderer_->renderDepth(empty, cam, fb).at(5, 5), 0.0F);
}

// DrawOptions::point_clouds draws only the clouds asked for (an empty cloud before them keeps the
// numbering: it is the scene's index that counts).
TEST_F(RenderTest, PointCloudMaskDrawsOnlyTheChosenClouds) {
  Scene scene;
  scene.background = Color(0, 0, 0, 1);
  scene.point_clouds.emplace_back();  // empty
  for (const double x : {-2.0, 2.0}) {
    PointCloud c;
    c.points = {{x, 0.0, 10.0}};
    c.colors = {Color(1, 1, 1, 1)};
    c.sizes_px = {9.0F};
    scene.point_clouds.push_back(c);
  }
  const GpuScene gpu(scene);
  PinholeIntrinsics K = kittiCamera();
  K.width = 160;
  K.height = 120;
  K.fx = K.fy = 100.0;
  K.cx = 79.5;
  K.cy = 59.5;
  const RenderCamera cam = pinholeCamera(K, Eigen::Isometry3d::Identity());
  Framebuffer fb(K.width, K.height);
  const auto lit = [](const ImageRgba& img, int x) { return img.pixel(x, 60)[0] > 128; };
  // x = -2 m and +2 m at 10 m: columns 79.5 -+ 20.
  const ImageRgba all = renderer_->renderColor(gpu, cam, fb);
  EXPECT_TRUE(lit(all, 80 - 20));
  EXPECT_TRUE(lit(all, 80 + 20));
  DrawOptions only_right;
  only_right.point_clouds = {true, false, true};
  const ImageRgba right = renderer_->renderColor(gpu, cam, fb, only_right);
  EXPECT_FALSE(lit(right, 80 - 20));
  EXPECT_TRUE(lit(right, 80 + 20));
}

Scene goldenScene() {
  Scene s;
  s.background = Color(1, 1, 1, 1);
  Polyline traj;
  for (int i = 0; i <= 60; ++i) {
    const double a = i * 0.1;
    traj.points.emplace_back(20 * std::cos(a), 12 * std::sin(a), 0.5);
  }
  traj.colors = {Color(0.1F, 0.3F, 0.9F, 1)};
  traj.widths_px = {4.0F};
  s.polylines.push_back(traj);
  PointCloud pc;
  for (int i = 0; i < 400; ++i)
    pc.points.emplace_back(-15 + (i % 20) * 1.5, -10 + (i / 20) * 1.0, 0.0);
  pc.colors = {Color(0.9F, 0.2F, 0.1F, 1)};
  pc.sizes_px = {3.0F};
  s.point_clouds.push_back(pc);
  VoxelSet vox;
  for (int i = 0; i < 5; ++i) vox.centers.emplace_back(5.0 + i, 3.0, 1.0 + 0.5 * i);
  vox.size_m = 1.0;
  vox.colors = {Color(0.2F, 0.8F, 0.3F, 1)};
  s.voxel_sets.push_back(vox);
  GroundGrid grid;
  grid.spacing_m = 5;
  grid.half_cells = 5;
  s.grids.push_back(grid);
  Frustum f;
  f.K = kittiCamera();
  f.T_w_c.linear() = (Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())).toRotationMatrix();
  f.depth_m = 4;
  s.frusta.push_back(f);
  return s;
}

cv::Mat toBgr(const ImageRgba& img) {
  cv::Mat rgba(img.height, img.width, CV_8UC4, const_cast<std::uint8_t*>(img.rgba.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

// Golden image with tolerance (drivers may differ in rasterisation details and MSAA patterns).
// Regenerate with GVIO_UPDATE_GOLDEN=1 after an intended change, and look at the new image.
TEST_F(RenderTest, GoldenImage) {
  const GpuScene gpu(goldenScene());
  const RenderCamera cam = orbitCamera(gpu.bounds(), 320, 240);
  Framebuffer fb(320, 240);
  const cv::Mat got = toBgr(renderer_->renderColor(gpu, cam, fb));
  const std::string golden = std::string(GVIO_SOURCE_DIR) + "/assets/golden/render_scene.png";
  if (std::getenv("GVIO_UPDATE_GOLDEN") != nullptr) cv::imwrite(golden, got);
  const cv::Mat want = cv::imread(golden, cv::IMREAD_COLOR);
  ASSERT_FALSE(want.empty()) << golden;
  cv::Mat diff;
  cv::absdiff(got, want, diff);
  EXPECT_LT(cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2], 6.0);
  cv::Mat big;
  cv::threshold(diff.reshape(1), big, 48, 1, cv::THRESH_BINARY);
  EXPECT_LT(cv::countNonZero(big), static_cast<int>(0.01 * got.total() * 3));
}

long residentKb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// The simulator renders thousands of frames from one context: memory must stay flat.
TEST_F(RenderTest, ManyFramesDoNotLeak) {
  const GpuScene gpu(goldenScene());
  Framebuffer fb(320, 240);
  const PinholeIntrinsics K = [] {
    PinholeIntrinsics k = kittiCamera();
    k.width = 320;
    k.height = 240;
    k.cx = 160;
    k.cy = 120;
    k.fx = k.fy = 200;
    return k;
  }();
  auto frame = [&](int i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.05 * i, -30, 2);
    return renderer_->renderColor(gpu, pinholeCamera(K, T), fb).rgba[0];
  };
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "resident memory is no measure under AddressSanitizer (it quarantines frees)";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  GTEST_SKIP() << "resident memory is no measure under AddressSanitizer (it quarantines frees)";
#endif
#endif
  for (int i = 0; i < 50; ++i) frame(i);  // warm-up: driver caches
  const long before = residentKb();
  for (int i = 0; i < 500; ++i) frame(i);
  EXPECT_LT(residentKb() - before, 8 * 1024) << "resident memory grew over 500 frames";
}

TEST_F(RenderTest, BadSizesAndScenes) {
  EXPECT_THROW(Framebuffer(0, 10), RenderError);
  EXPECT_THROW(Framebuffer(10, 16385), RenderError);
  EXPECT_THROW(topDownCamera(Eigen::AlignedBox3d(), 100, 100), RenderError);
  PinholeIntrinsics bad;
  EXPECT_THROW(pinholeCamera(bad, Eigen::Isometry3d::Identity()), RenderError);
  Scene s;
  PointCloud pc;
  pc.points = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  pc.colors = {Color(1, 0, 0, 1), Color(0, 1, 0, 1)};  // neither 1 nor 3
  s.point_clouds.push_back(pc);
  EXPECT_THROW(GpuScene{s}, RenderError);
  Framebuffer fb(64, 48);
  const GpuScene gpu(goldenScene());
  EXPECT_THROW(renderer_->draw(gpu, orbitCamera(gpu.bounds(), 32, 32), fb), RenderError);
}

}  // namespace
}  // namespace gvio::render
