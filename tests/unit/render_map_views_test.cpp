// Map views of `gvio render` (topdown with map, perspective cloud, OctoMap voxels) built from a
// synthetic run folder (render_map_fixture.hpp) and rendered on whatever EGL offers (llvmpipe in
// CI) at 320x240: known geometry must show up, in its colour, where the view's camera puts it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "odometry/error.hpp"
#include "render/annotate.hpp"
#include "render/camera.hpp"
#include "render/renderer.hpp"
#include "render_map_fixture.hpp"
#include "support/render_fixture.hpp"
#include "viz/map_layers.hpp"
#include "viz/run_views.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using viz::RunView;

constexpr int kW = 320, kH = 240;

class RenderMapViews : public SharedRendererTest {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("rendermap");
    writeSyntheticMapRun(dir_->path() / "run");
    SharedRendererTest::SetUpTestSuite();
  }
  static void TearDownTestSuite() {
    SharedRendererTest::TearDownTestSuite();
    dir_.reset();
  }
  static io::RunFiles run() { return io::readRunDir(dir_->path() / "run"); }
  static render::ImageRgba draw(const viz::ViewSpec& v) {
    const render::GpuScene gpu(v.scene);
    render::Framebuffer fb(v.camera.width, v.camera.height);
    render::ImageRgba img = renderer_->renderColor(gpu, v.camera, fb);
    if (const char* debug = std::getenv("GVIO_RENDER_DEBUG")) {  // a folder to look at them in
      const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
      cv::Mat rgba(img.height, img.width, CV_8UC4, img.rgba.data()), bgr;
      cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
      cv::imwrite(std::string(debug) + "/" + info->name() + ".png", bgr);
    }
    return img;
  }
  static std::unique_ptr<TempDir> dir_;
};
std::unique_ptr<TempDir> RenderMapViews::dir_;

// Colour (0..1) of the pixel where `camera` projects `p`; fails the test when it is off-image.
Eigen::Vector3d colourAt(const render::ImageRgba& img, const render::RenderCamera& camera,
                         const Eigen::Vector3d& p) {
  const Eigen::Vector2d uv = render::projectToPixel(camera, p);
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  EXPECT_TRUE(u >= 0 && u < img.width && v >= 0 && v < img.height)
      << "(" << p.transpose() << ") projects off the image to " << uv.transpose();
  if (u < 0 || u >= img.width || v < 0 || v >= img.height) return Eigen::Vector3d::Constant(-1);
  const std::uint8_t* px = img.pixel(u, v);
  return Eigen::Vector3d(px[0], px[1], px[2]) / 255.0;
}

Eigen::Vector3d toVec(const render::Rgb& c) {
  return {c.r, c.g, c.b};
}

bool isBackground(const Eigen::Vector3d& c) {
  return (c.array() > 0.98).all();  // the views' white
}

Eigen::Vector3d legendColour(const viz::ViewSpec& v, const std::string& prefix) {
  for (const auto& e : v.annotations.legend) {
    if (e.label.rfind(prefix, 0) == 0) return toVec(e.color);
  }
  ADD_FAILURE() << "no legend entry starting with '" << prefix << "'";
  return Eigen::Vector3d::Constant(-1);
}

Eigen::Vector3d viridisOfHeight(const viz::ViewSpec& v, double z) {
  const auto& bar = *v.annotations.color_bar;
  return toVec(render::colormap(render::ColorMap::kViridis, render::normalise(z, bar.lo, bar.hi)));
}

MATCHER_P2(ColourNear, want, tol, "") {
  return (arg - want).cwiseAbs().maxCoeff() <= tol;
}

TEST_F(RenderMapViews, TopDownDrawsHeightColouredMapWithFixesAndOutagesOnTop) {
  const viz::ViewSpec v = viz::buildRunView(run(), RunView::kTopDown, kW, kH);
  ASSERT_TRUE(v.annotations.color_bar.has_value());
  // The colour scale spans the 1st-99th height percentiles: ground 0 m to wall top 6 m, without
  // the 10 stray landmarks at 10 m.
  EXPECT_NEAR(v.annotations.color_bar->lo, 0.0, 1e-6);
  EXPECT_NEAR(v.annotations.color_bar->hi, 6.0, 1e-6);
  EXPECT_THAT(v.annotations.legend,
              testing::Contains(testing::Field(&render::LegendEntry::label, "GNSS used (3)")));
  EXPECT_THAT(v.annotations.legend,
              testing::Contains(testing::Field(&render::LegendEntry::label, "GNSS not fused (1)")));
  const render::ImageRgba img = draw(v);
  const auto& cam = v.camera;
  EXPECT_THAT(colourAt(img, cam, {20, -6, 0}), ColourNear(viridisOfHeight(v, 0.0), 0.03));
  EXPECT_THAT(colourAt(img, cam, {42, -5, 6}), ColourNear(viridisOfHeight(v, 6.0), 0.03));
  EXPECT_THAT(colourAt(img, cam, {15, -3, 0}), ColourNear(legendColour(v, "GNSS used"), 0.03));
  EXPECT_THAT(colourAt(img, cam, {20, 4, 0}), ColourNear(legendColour(v, "GNSS rejected"), 0.03));
  // The outage (20..28 s) recolours the drive between x = 22 and 30; before it, the fused line.
  EXPECT_THAT(colourAt(img, cam, {25, 0, 0}), ColourNear(legendColour(v, "GNSS outage"), 0.03));
  EXPECT_THAT(colourAt(img, cam, {10, 0, 0}), ColourNear(legendColour(v, "fused"), 0.03));
  // Beyond the map (the view is wider than the map is tall): background.
  EXPECT_TRUE(isBackground(colourAt(img, cam, {22.5, -17.5, 0})));  // between grid lines
  EXPECT_FALSE(isBackground(colourAt(img, cam, {2, -9.5, 0})));     // the map's corner is in view
}

TEST_F(RenderMapViews, TopDownWithoutMapIsTheTrajectoryView) {
  io::RunFiles r = run();
  r.cloud.reset();
  const viz::ViewSpec v = viz::buildRunView(r, RunView::kTopDown, kW, kH);
  EXPECT_FALSE(v.annotations.color_bar.has_value());
  const render::ImageRgba img = draw(v);
  EXPECT_THAT(colourAt(img, v.camera, {10, 0, 0}), ColourNear(legendColour(v, "fused"), 0.03));
  EXPECT_TRUE(isBackground(colourAt(img, v.camera, {11, -1, 0})));  // no ground any more
}

// The drawing stays clear of the overlays: no pose under the compass / colour bar column (the
// right 10 annotation units) or the title strip (the top 5), for a drive wider than the image's
// aspect and for one taller.
TEST_F(RenderMapViews, TopDownKeepsTheDrawingClearOfTheOverlays) {
  const double unit = render::annotationUnitPx(kW, kH);
  for (const Eigen::Vector3d& step : {Eigen::Vector3d(3, 0.2, 0), Eigen::Vector3d(0.2, 3, 0)}) {
    io::RunFiles r = run();
    r.cloud.reset();
    r.fused = Trajectory();
    for (int k = 0; k <= 100; ++k) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = k * step;
      r.fused->t_ns.push_back(k * 100'000'000LL);
      r.fused->poses.push_back(T);
    }
    const viz::ViewSpec v = viz::buildRunView(r, RunView::kTopDown, kW, kH);
    for (const Eigen::Isometry3d& T : r.fused->poses) {
      const Eigen::Vector2d px = render::projectToPixel(v.camera, T.translation());
      EXPECT_GE(px.x(), 0.0);
      EXPECT_LE(px.x(), kW - 10.0 * unit) << T.translation().transpose();
      EXPECT_GE(px.y(), 5.0 * unit) << T.translation().transpose();
      EXPECT_LE(px.y(), kH);
    }
  }
}

TEST_F(RenderMapViews, PerspectiveSeesTheWallAheadFromBehindAndAbove) {
  const viz::ViewSpec v = viz::buildRunView(run(), RunView::kPerspective, kW, kH);
  const Eigen::Vector3d eye = v.camera.view.inverse().topRightCorner<3, 1>();
  EXPECT_LT(eye.x(), 2.0) << "camera not behind the start (the drive heads east from x = 2)";
  EXPECT_GT(eye.z(), 5.0) << "camera not above the map";
  const render::ImageRgba img = draw(v);
  const auto& cam = v.camera;
  // Intensity 255 leaves the height colour unshaded.
  EXPECT_THAT(colourAt(img, cam, {42, -4, 3}), ColourNear(viridisOfHeight(v, 3.0), 0.08));
  // Near the top, rows 0.25 m apart overlap on screen and the upper (nearer) one wins.
  EXPECT_THAT(colourAt(img, cam, {42, -4, 5.5}), ColourNear(viridisOfHeight(v, 5.75), 0.08));
  EXPECT_THAT(colourAt(img, cam, {20, -6, 0}), ColourNear(viridisOfHeight(v, 0.0), 0.08));
  // Sparse landmarks stay out of a dense view; nothing is drawn above the wall.
  EXPECT_TRUE(isBackground(colourAt(img, cam, {20.5, 9, 10})));
  EXPECT_TRUE(isBackground(colourAt(img, cam, {42, -4, 11})));
  // Fitted: the map's corners are in view and the map fills a good part of it.
  for (const double x : {0.0, 42.0}) {
    for (const double y : {-10.0, 10.0}) {
      const Eigen::Vector2d uv = render::projectToPixel(cam, {x, y, 0});
      EXPECT_TRUE(uv.x() >= 0 && uv.x() < kW && uv.y() >= 0 && uv.y() < kH) << x << " " << y;
    }
  }
  int drawn = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) drawn += img.pixel(x, y)[0] < 250 ? 1 : 0;
  }
  EXPECT_GT(drawn, kW * kH / 6);
}

TEST_F(RenderMapViews, PerspectiveWithoutMapIsTheTrajectoryOrbit) {
  io::RunFiles r = run();
  r.cloud.reset();
  const viz::ViewSpec v = viz::buildRunView(r, RunView::kPerspective, kW, kH);
  EXPECT_FALSE(v.annotations.color_bar.has_value());
  EXPECT_EQ(v.scene.point_clouds.size(), 1U);  // start/end discs only
}

TEST_F(RenderMapViews, OctomapViewDrawsTheTreeColouredVoxels) {
  const viz::ViewSpec v = viz::buildRunView(run(), RunView::kOctomap, kW, kH);
  // 0.5 m voxels are above a pixel here: drawn as they are (OctoMap pruned the uniform red block
  // into one 1 m leaf).
  double volume = 0.0;
  for (const auto& s : v.scene.voxel_sets) {
    EXPECT_GE(s.size_m, 0.5);
    volume += static_cast<double>(s.centers.size()) * std::pow(s.size_m, 3);
  }
  EXPECT_NEAR(volume, (8 + 64) * 0.125, 1e-9);
  EXPECT_FALSE(v.annotations.color_bar.has_value());  // the ColorOcTree's own colours
  const render::ImageRgba img = draw(v);
  const Eigen::Vector3d red = colourAt(img, v.camera, {6.5, -3.5, 0.5});
  EXPECT_GT(red.x(), 3.0 * red.y()) << red.transpose();
  EXPECT_GT(red.x(), 3.0 * red.z()) << red.transpose();
  const Eigen::Vector3d blue = colourAt(img, v.camera, {22.0, 6.25, 2.0});
  EXPECT_GT(blue.z(), 3.0 * blue.x()) << blue.transpose();
  EXPECT_TRUE(isBackground(colourAt(img, v.camera, {14, 0, 12})));
}

TEST_F(RenderMapViews, OctomapFromBinaryTreeIsHeightColoured) {
  const fs::path bt_run = dir_->path() / "bt_run";
  fs::create_directories(bt_run);
  io::writeTum(bt_run / "trajectory.tum", syntheticDrive());
  writeOcTreeBinary(bt_run / "map.bt");
  const viz::ViewSpec v = viz::buildRunView(io::readRunDir(bt_run), RunView::kOctomap, kW, kH);
  ASSERT_TRUE(v.annotations.color_bar.has_value());
  const render::ImageRgba img = draw(v);
  // The slab's top (4 m, the highest voxels) in viridis' yellow, shaded: green above blue.
  const Eigen::Vector3d top = colourAt(img, v.camera, {22.0, 6.25, 3.9});
  EXPECT_GT(top.y(), 2.0 * top.z()) << top.transpose();
}

TEST_F(RenderMapViews, OctomapViewNeedsAnOctree) {
  io::RunFiles r = run();
  r.occupancy.reset();
  EXPECT_THAT([&] { viz::buildRunView(r, RunView::kOctomap, kW, kH); },
              testing::ThrowsMessage<InvalidInput>(testing::HasSubstr("needs map.ot or map.bt")));
}

TEST(RenderMapLayers, SubPixelVoxelsMergeIntoOctreeCells) {
  EXPECT_DOUBLE_EQ(viz::lodCellSize(0.2, 0.1), 0.2);
  EXPECT_DOUBLE_EQ(viz::lodCellSize(0.2, 0.5), 0.8);
  io::OccupancyMap map;
  map.resolution_m = 0.25;
  map.has_color = true;
  for (int i = 0; i < 64; ++i) {  // a 4x4x4 block filling the cell [1, 2)^3, half red half blue
    io::OccupiedVoxel v;
    v.center_enu = Eigen::Vector3f(1.125F + 0.25F * static_cast<float>(i % 4),
                                   1.125F + 0.25F * static_cast<float>((i / 4) % 4),
                                   1.125F + 0.25F * static_cast<float>(i / 16));
    v.size_m = 0.25F;
    v.rgb =
        i < 32 ? std::array<std::uint8_t, 3>{200, 0, 0} : std::array<std::uint8_t, 3>{0, 0, 100};
    map.voxels.push_back(v);
  }
  io::OccupiedVoxel big;  // a pruned 2 m leaf keeps its size
  big.center_enu = Eigen::Vector3f(5, 5, 1);
  big.size_m = 2.0F;
  map.voxels.push_back(big);
  viz::VoxelStyle style;
  style.min_size_m = 0.9;
  const auto sets = viz::voxelSets(map, style);
  ASSERT_EQ(sets.size(), 2U);
  EXPECT_DOUBLE_EQ(sets[0].size_m, 1.0);
  ASSERT_EQ(sets[0].centers.size(), 1U);
  EXPECT_TRUE(sets[0].centers[0].isApprox(Eigen::Vector3d(1.5, 1.5, 1.5)));
  EXPECT_NEAR(sets[0].colors[0][0], 100.0 / 255.0, 1e-6);  // mean colour
  EXPECT_NEAR(sets[0].colors[0][2], 50.0 / 255.0, 1e-6);
  EXPECT_DOUBLE_EQ(sets[1].size_m, 2.0);
  EXPECT_EQ(sets[1].centers.size(), 1U);
}

TEST(RenderMapLayers, OnlyTheNearestPointOfAPixelIsKept) {
  const std::vector<Eigen::Vector3f> p = {{0, 0, 0},  {0, 0, 5},     {0, 0, 2},
                                          {10, 0, 0}, {100, 100, 0}, {10.01F, 0, 3}};
  // From above the nearest is the highest; points off the image go.
  const auto top = render::topDownCamera(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(11, 1, 6)), 120, 20);
  EXPECT_EQ(viz::nearestPerPixel(p, top), (std::vector<std::uint32_t>{1, 5}));
  const std::vector<std::uint32_t> among = {0, 2, 3};
  EXPECT_EQ(viz::nearestPerPixel(p, top, &among), (std::vector<std::uint32_t>{2, 3}));
  // Looking east along the x axis from x = -5: (0, 0, 0) hides (10, 0, 0).
  render::PinholeIntrinsics K;
  K.fx = K.fy = 50;
  K.cx = K.cy = 31.5;
  K.width = K.height = 64;
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  T_w_c.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // camera z east, x south, y down
  T_w_c.translation() = Eigen::Vector3d(-5, 0, 0);
  const std::vector<Eigen::Vector3f> row = {{10, 0, 0}, {0, 0, 0}, {-10, 0, 0}};
  EXPECT_EQ(viz::nearestPerPixel(row, render::pinholeCamera(K, T_w_c)),
            (std::vector<std::uint32_t>{1}));  // behind the camera: dropped
}

TEST(RenderMapLayers, RobustBoundsAndPointSizes) {
  std::vector<Eigen::Vector3f> p;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j)
      p.emplace_back(0.5F * static_cast<float>(i), 0.5F * static_cast<float>(j), 0.0F);
  }
  for (int i = 0; i < 5; ++i) p.emplace_back(1e4F, -1e4F, 500.0F);  // stray stereo matches
  const Eigen::AlignedBox3d b = viz::quantileBounds(p);
  EXPECT_LE(b.max().x(), 19.5);
  EXPECT_GE(b.min().y(), 0.0);
  EXPECT_LE(b.max().z(), 0.0);
  EXPECT_NEAR(viz::typicalSpacingM(p, 2.0), 0.5, 1e-6);
  EXPECT_DOUBLE_EQ(viz::typicalSpacingM(p, 0.3), 0.3);  // neighbours farther than the search
  EXPECT_EQ(viz::pointSizePx(0.5, 0.25), 3.0F);
  EXPECT_EQ(viz::pointSizePx(0.01, 0.25), 2.0F);
  EXPECT_EQ(viz::pointSizePx(10.0, 0.25), 5.0F);
}

}  // namespace
}  // namespace gvio::test
