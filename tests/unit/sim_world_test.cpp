// sim/world: the procedural street is deterministic, keeps the road (crossings and revisits
// included) free, and renders images on which Shi-Tomasi corners and pyramidal KLT behave as on
// real streets (KITTI camera; 1 m between frames, and KITTI 00's own 10 Hz frames).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "odometry/error.hpp"
#include "render/renderer.hpp"
#include "sim/kitti_convention.hpp"
#include "sim/textures.hpp"
#include "sim/world.hpp"
#include "sim_world_fixture.hpp"
#include "support/render_fixture.hpp"

namespace gvio::sim {
namespace {

using namespace world_fixture;  // NOLINT(google-build-using-namespace): test helpers

TEST(SimWorldTest, SameSeedSameWorldOtherSeedOtherWorld) {
  const auto route = twoTurns();
  WorldOptions o;
  o.texture_size_px = 128;
  const World a = buildWorld(route, o), b = buildWorld(route, o);
  ASSERT_EQ(a.scene.meshes.size(), b.scene.meshes.size());
  EXPECT_GT(a.triangles, 1000U);
  for (std::size_t i = 0; i < a.scene.meshes.size(); ++i) {
    const auto &ma = a.scene.meshes[i], &mb = b.scene.meshes[i];
    EXPECT_EQ(ma.texture, mb.texture);
    EXPECT_EQ(ma.indices, mb.indices);
    ASSERT_EQ(ma.vertices.size(), mb.vertices.size());
    EXPECT_EQ(0, std::memcmp(ma.vertices.data(), mb.vertices.data(),
                             ma.vertices.size() * sizeof(Eigen::Vector3d)));
    EXPECT_EQ(0, std::memcmp(ma.uv.data(), mb.uv.data(), ma.uv.size() * sizeof(Eigen::Vector2f)));
  }
  ASSERT_EQ(a.scene.textures.size(), b.scene.textures.size());
  for (std::size_t i = 0; i < a.scene.textures.size(); ++i)
    EXPECT_EQ(a.scene.textures[i].data, b.scene.textures[i].data);

  o.seed = 2;
  const World c = buildWorld(route, o);
  EXPECT_NE(a.scene.textures[0].data, c.scene.textures[0].data);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < std::min(a.scene.meshes.size(), c.scene.meshes.size()); ++i)
    differing += a.scene.meshes[i].vertices != c.scene.meshes[i].vertices ? 1 : 0;
  EXPECT_GT(differing, 0U);
}

TEST(SimWorldTest, NothingStandsOnTheRoadWhereTheRouteCrossesItself) {
  for (const auto& route : {twoTurns(), figureEight()}) {
    WorldOptions o;
    o.texture_size_px = 64;
    const World world = buildWorld(route, o);
    EXPECT_EQ(verticesOnRoad(world, route, o.road_half_width_m, o.body_height_m), 0U);
  }
}

// A block driven twice gets one row of buildings, not two: no building overlaps another (row
// neighbours may touch), and the second pass only fills gaps the first one left.
TEST(SimWorldTest, RevisitedStreetsAreNotBuiltTwice) {
  WorldOptions o;
  o.texture_size_px = 64;
  const World once = buildWorld(block(1), o), both = buildWorld(block(2), o);
  const TextureLibrary lib = makeTextureLibrary(o.seed, 64);
  const auto a = buildingFootprints(once, lib.facade_front);
  const auto b = buildingFootprints(both, lib.facade_front);
  std::cout << "[ revisit ] buildings: block driven once " << a.size() << ", twice " << b.size()
            << "\n";
  EXPECT_GT(a.size(), 40U);
  EXPECT_LT(static_cast<double>(b.size()), 1.5 * static_cast<double>(a.size()));
  EXPECT_LT(deepestBuildingOverlap(b), 0.15);
  EXPECT_EQ(verticesOnRoad(both, block(2), o.road_half_width_m, o.body_height_m), 0U);
}

TEST(SimWorldTest, RejectsBadInput) {
  WorldOptions o;
  EXPECT_THROW(buildWorld({}, o), InvalidInput);
  EXPECT_THROW(buildWorld({Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)}, o), InvalidInput);
  o.texture_size_px = 300;
  EXPECT_THROW(buildWorld(twoTurns(), o), InvalidInput);
}

TEST(SimWorldTest, TexturesHaveContrastAndAreDeterministic) {
  const TextureLibrary a = makeTextureLibrary(7, 128), b = makeTextureLibrary(7, 128);
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (std::size_t i = 0; i < a.textures.size(); ++i) {
    EXPECT_EQ(a.textures[i].data, b.textures[i].data);
    const cv::Mat m(a.textures[i].height, a.textures[i].width, CV_8UC1,
                    const_cast<std::uint8_t*>(a.textures[i].data.data()));
    cv::Scalar mean, stddev;
    cv::meanStdDev(m, mean, stddev);
    EXPECT_GT(stddev[0], 6.0) << "texture " << i << " is nearly flat";
  }
  EXPECT_THROW(makeTextureLibrary(1, 100), InvalidInput);
}

// ---- Rendering: one EGL context for the suite ----

render::PinholeIntrinsics kittiCamera() {
  return sim::kittiIntrinsics();
}

// One EGL context and renderer for the suite (support/render_fixture.hpp).
class SimWorldRenderTest : public test::SharedRendererTest {
 protected:
  cv::Mat render(const render::GpuScene& gpu, const Eigen::Isometry3d& T_w_c) const {
    const render::PinholeIntrinsics K = kittiCamera();
    render::Framebuffer fb(K.width, K.height);
    return greyOf(renderer_->renderColor(gpu, render::pinholeCamera(K, T_w_c), fb));
  }
  // Top view of the route's surroundings with the route drawn on top.
  void saveTopDown(const World& world, const std::vector<Eigen::Vector3d>& route,
                   const std::string& file) const {
    render::Scene scene = world.scene;
    render::Polyline line;
    for (const auto& p : route) line.points.push_back(p + Eigen::Vector3d(0, 0, 40));
    line.colors = {render::Color(1, 0, 0, 1)};
    scene.polylines.push_back(line);
    Eigen::AlignedBox3d box;
    for (const auto& p : route) box.extend(p);
    box.min() -= Eigen::Vector3d(70, 70, 2);
    box.max() += Eigen::Vector3d(70, 70, 45);
    const render::GpuScene gpu(scene);
    const int w = 1600, h = static_cast<int>(1600 * box.sizes().y() / box.sizes().x());
    render::Framebuffer fb(w, std::clamp(h, 200, 4000));
    const auto img = renderer_->renderColor(gpu, render::topDownCamera(box, w, fb.height()), fb);
    cv::Mat rgba(img.height, img.width, CV_8UC4, const_cast<std::uint8_t*>(img.rgba.data())), bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    cv::imwrite(file, bgr);
  }
};

struct ViewStats {
  int corners = 0, bottom = 0, top = 0;  // all, in the bottom third, in the top half
  double klt_kept = 0.0;                 // fraction tracked into the next frame
};

// Shi-Tomasi corners in `a`, tracked into `b` by pyramidal KLT (OpenCV defaults: 21 x 21, 3
// levels). With a debug name, writes `a` with kept (green) and lost (red) corners.
ViewStats cornersAndKlt(const cv::Mat& a, const cv::Mat& b, const std::string& debug_name) {
  std::vector<cv::Point2f> corners, next;
  cv::goodFeaturesToTrack(a, corners, 2000, 0.01, 10);
  ViewStats v;
  if (corners.empty()) return v;
  std::vector<std::uint8_t> status;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(a, b, corners, next, status, err);
  v.corners = static_cast<int>(corners.size());
  const auto rows = static_cast<float>(a.rows);
  for (const auto& c : corners) {
    v.bottom += c.y > 2.0F * rows / 3.0F ? 1 : 0;
    v.top += c.y < 0.5F * rows ? 1 : 0;
  }
  v.klt_kept = static_cast<double>(std::count(status.begin(), status.end(), 1)) / v.corners;
  if (!debug_name.empty()) {
    cv::Mat vis;
    cv::cvtColor(a, vis, cv::COLOR_GRAY2BGR);
    for (std::size_t k = 0; k < corners.size(); ++k)
      cv::circle(vis, corners[k], 3, status[k] ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255));
    cv::imwrite(debug_name, vis);
  }
  return v;
}

// Worst and mean over views; every view must have >= 300 corners, >= 20 of them in the bottom
// third (road, near) and in the top half (facades, far), and KLT must keep >= 80 %.
struct Summary {
  ViewStats worst{1 << 30, 1 << 30, 1 << 30, 1.0};
  double corners = 0.0, klt = 0.0;
  int views = 0;

  void add(const ViewStats& v, const std::string& label, bool print) {
    if (print) {
      std::cout << "  " << label << ": " << v.corners << " corners (" << v.bottom << " bottom, "
                << v.top << " top), KLT kept " << v.klt_kept << "\n";
    }
    EXPECT_GE(v.corners, 300) << label;
    EXPECT_GE(v.bottom, 20) << label;
    EXPECT_GE(v.top, 20) << label;
    EXPECT_GE(v.klt_kept, 0.8) << label;
    worst = {std::min(worst.corners, v.corners), std::min(worst.bottom, v.bottom),
             std::min(worst.top, v.top), std::min(worst.klt_kept, v.klt_kept)};
    corners += v.corners;
    klt += v.klt_kept;
    ++views;
  }
  [[nodiscard]] std::string text() const {
    std::ostringstream o;
    o << views << " views: corners min " << worst.corners << " mean " << corners / views << " (min "
      << worst.bottom << " in the bottom third, " << worst.top << " in the top half); KLT kept min "
      << worst.klt_kept << " mean " << klt / views;
    return o.str();
  }
};

// 20 views along a street with two turns: enough corners everywhere in the image, and KLT keeps
// them from one frame to the next 1 m further. GVIO_SIM_DEBUG=1 writes every view.
TEST_F(SimWorldRenderTest, CornersAndKltAlongTheStreet) {
  const auto route = twoTurns();
  const World world = buildWorld(route, WorldOptions{});
  const render::GpuScene gpu(world.scene);
  const bool debug = std::getenv("GVIO_SIM_DEBUG") != nullptr;
  Summary summary;
  for (int i = 0; i < 20; ++i) {
    const double s = 15.0 + i * 18.5;
    const cv::Mat a = render(gpu, cameraAt(route, s)), b = render(gpu, cameraAt(route, s + 1.0));
    if (i == 7) cv::imwrite("/tmp/sim_world_view.png", a);
    const std::string name = debug ? "/tmp/sim_world_klt_" + std::to_string(i) + ".png" : "";
    summary.add(cornersAndKlt(a, b, name), "view " + std::to_string(i), debug);
  }
  std::cout << "[ sim world ] " << world.triangles << " triangles; " << summary.text() << "\n";
  saveTopDown(world, route, "/tmp/sim_world_topdown.png");
}

// The real drive (KITTI 00, 3.7 km, crossing and revisiting its streets): triangle budget, build
// time, a free road, and corners and KLT between consecutive ground-truth frames (10 Hz).
TEST_F(SimWorldRenderTest, Kitti00Drive) {
  const std::filesystem::path gt = std::string(GVIO_SHARED_DATA_DIR) + "/kitti00/KITTI_00_gt.txt";
  if (!std::filesystem::exists(gt)) GTEST_SKIP() << gt << " not found";
  const auto poses = kittiCameraPoses(gt);
  ASSERT_GT(poses.size(), 4000U);
  std::vector<Eigen::Vector3d> route;  // body positions: the camera is 1.65 m above the road
  for (const auto& T : poses)
    route.push_back(T.translation() - Eigen::Vector3d(0, 0, kCameraHeight - kBodyHeight));
  const auto t0 = std::chrono::steady_clock::now();
  const World world = buildWorld(route, WorldOptions{});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ kitti 00 ] " << world.triangles << " triangles in " << world.scene.meshes.size()
            << " meshes, built in " << seconds << " s\n";
  EXPECT_LT(world.triangles, 1500000U);
  // Objects only: KITTI's recorded heights differ between passes of nearby streets (up to ~1.7 m
  // 12 m apart), so the street surfaces there follow a blended height field.
  const TextureLibrary lib = makeTextureLibrary(WorldOptions{}.seed, 64);
  const std::vector<std::size_t> surfaces{lib.asphalt, lib.marking, lib.paving, lib.curb,
                                          lib.ground};
  EXPECT_EQ(verticesOnRoad(world, route, 4.5, kBodyHeight, surfaces), 0U);
  const auto buildings = buildingFootprints(world, lib.facade_front);
  std::cout << "[ kitti 00 ] " << buildings.size() << " buildings\n";
  EXPECT_LT(deepestBuildingOverlap(buildings), 0.15);

  const render::GpuScene gpu(world.scene);
  const bool debug = std::getenv("GVIO_SIM_DEBUG") != nullptr;
  Summary summary;
  const auto r0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 40; ++i) {
    const std::size_t k = 20 + static_cast<std::size_t>(i) * (poses.size() - 40) / 40;
    const std::string name = debug ? "/tmp/sim_world_kitti_" + std::to_string(k) + ".png" : "";
    summary.add(cornersAndKlt(render(gpu, poses[k]), render(gpu, poses[k + 1]), name),
                "frame " + std::to_string(k), debug);
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - r0).count();
  std::cout << "[ kitti 00 ] frame pairs, " << summary.text() << "; " << ms / 80.0
            << " ms per frame incl. features (" << context_->info().gl_renderer << ")\n";
  if (debug) saveTopDown(world, route, "/tmp/sim_world_kitti_topdown.png");
}

}  // namespace
}  // namespace gvio::sim
