// Accepted loop closures (loops.csv) in `gvio render --view topdown`, rendered on whatever EGL
// offers (llvmpipe in CI) at 320x240: a segment in the loop colour between the two keyframes of
// each accepted loop, none for rejected candidates, and the legend counting what is drawn.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>

#include "io/loops_csv.hpp"
#include "io/run_dir.hpp"
#include "io/trajectory_io.hpp"
#include "render/camera.hpp"
#include "support/fixtures.hpp"
#include "support/render_fixture.hpp"
#include "viz/loop_layer.hpp"
#include "viz/run_views.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using testing::Contains;
using testing::Field;

constexpr int kW = 320, kH = 240;
constexpr std::int64_t kSecond = 1'000'000'000LL;

// One pose a second: east along y = 0 to x = 40 (t 0..40), north to y = 20 (t 60), west to x = 0
// (t 100), south to y = 6 (t 114): back at the start, but with 6 m of drift northwards. Then east
// again along y = 6 to x = 20 (t 134), 6 m beside the first pass.
Eigen::Vector2d loopingDriveAt(int t_s) {
  const double t = t_s;
  if (t <= 40) return {t, 0.0};
  if (t <= 60) return {40.0, t - 40};
  if (t <= 100) return {40 - (t - 60), 20.0};
  if (t <= 114) return {0.0, 20 - (t - 100)};
  return {t - 114, 6.0};
}

Trajectory loopingDrive() {
  Trajectory traj;
  for (int t = 0; t <= 134; ++t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << loopingDriveAt(t), 1.0;
    traj.poses.push_back(T);
    traj.t_ns.push_back(t * kSecond);
  }
  return traj;
}

io::LoopCsvRow loop(std::int64_t query_ns, std::int64_t candidate_ns, bool accepted) {
  io::LoopCsvRow r;
  r.query_t_ns = query_ns;
  r.candidate_t_ns = candidate_ns;
  r.accepted = accepted;
  r.reason = accepted ? "ok" : "inconsistent";
  return r;
}

// Accepted: the return to the start (114.1 s, 0.1 s off its keyframe pose -> (0, 6), with (0, 0))
// and the second pass (124 s (10, 6) with 10 s (10, 0)). Rejected: 134 s (20, 6) with 20 s (20, 0).
std::vector<io::LoopCsvRow> loops() {
  return {loop(114 * kSecond + 100'000'000LL, 0, true), loop(124 * kSecond, 10 * kSecond, true),
          loop(134 * kSecond, 20 * kSecond, false)};
}

class RenderLoops : public SharedRendererTest {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("renderloops");
    fs::create_directories(dir_->path() / "run");
    io::writeTum(dir_->path() / "run" / "trajectory.tum", loopingDrive());
    io::writeLoopsCsv(dir_->path() / "run" / "loops.csv", loops());
    SharedRendererTest::SetUpTestSuite();
  }
  static void TearDownTestSuite() {
    SharedRendererTest::TearDownTestSuite();
    dir_.reset();
  }
  static io::RunFiles run() {
    return io::readRunDir(dir_->path() / "run",
                          viz::readOptionsFor(viz::RunView::kTopDown, std::nullopt));
  }
  static render::ImageRgba draw(const viz::ViewSpec& v) {
    const render::GpuScene gpu(v.scene);
    render::Framebuffer fb(v.camera.width, v.camera.height);
    return renderer_->renderColor(gpu, v.camera, fb);
  }
  static std::unique_ptr<TempDir> dir_;
};
std::unique_ptr<TempDir> RenderLoops::dir_;

// Colour (0..1) of the pixel where `camera` projects (x, y); fails the test when it is off-image.
Eigen::Vector3d colourAt(const render::ImageRgba& img, const render::RenderCamera& camera, double x,
                         double y) {
  const Eigen::Vector2d uv = render::projectToPixel(camera, Eigen::Vector3d(x, y, 0));
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  EXPECT_TRUE(u >= 0 && u < img.width && v >= 0 && v < img.height) << x << " " << y;
  if (u < 0 || u >= img.width || v < 0 || v >= img.height) return Eigen::Vector3d::Constant(-1);
  const std::uint8_t* px = img.pixel(u, v);
  return Eigen::Vector3d(px[0], px[1], px[2]) / 255.0;
}

Eigen::Vector3d loopColour(const viz::ViewSpec& v) {
  for (const auto& e : v.annotations.legend) {
    if (e.label.rfind("loop closures", 0) == 0) return {e.color.r, e.color.g, e.color.b};
  }
  ADD_FAILURE() << "no legend entry 'loop closures'";
  return Eigen::Vector3d::Constant(-1);
}

double colourDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST_F(RenderLoops, TopDownDrawsAcceptedLoopsOnly) {
  const io::RunFiles r = run();
  ASSERT_TRUE(r.loops.has_value());
  ASSERT_EQ(r.loops->size(), 3U);
  const viz::ViewSpec v = viz::buildRunView(r, viz::RunView::kTopDown, kW, kH);
  EXPECT_THAT(v.annotations.legend,
              Contains(Field(&render::LegendEntry::label, "loop closures (2)")));
  const Eigen::Vector3d pink = loopColour(v);
  const render::ImageRgba img = draw(v);
  // Midpoint and quarter points of each accepted segment (x = 0 and x = 10, y 0..6).
  for (const double x : {0.0, 10.0}) {
    for (const double y : {1.5, 3.0, 4.5}) {
      EXPECT_LE(colourDistance(colourAt(img, v.camera, x, y), pink), 0.03) << x << " " << y;
    }
  }
  // Not on the rejected one (x = 20), nor between the passes elsewhere.
  for (const double y : {1.5, 3.0, 4.5}) {
    EXPECT_GT(colourDistance(colourAt(img, v.camera, 20.0, y), pink), 0.3) << y;
    EXPECT_GT(colourDistance(colourAt(img, v.camera, 15.0, y), pink), 0.3) << y;
  }
}

TEST_F(RenderLoops, LoopsFollowTheMainTrajectoryAndSkipUnplacedStamps) {
  io::RunFiles r = run();
  r.loops->push_back(loop(500 * kSecond, 10 * kSecond, true));      // past the end of the drive
  r.loops->push_back(loop(30 * kSecond + 300'000'000LL, 0, true));  // 0.3 s from any pose
  viz::ViewSpec v = viz::buildRunView(r, viz::RunView::kTopDown, kW, kH);
  EXPECT_THAT(v.annotations.legend,
              Contains(Field(&render::LegendEntry::label, "loop closures (2)")));
  // Without trajectory.tum the VIO trajectory is the map's: the loops are drawn on it.
  r.vio = r.fused;
  r.fused.reset();
  v = viz::buildRunView(r, viz::RunView::kTopDown, kW, kH);
  const render::ImageRgba img = draw(v);
  EXPECT_LE(colourDistance(colourAt(img, v.camera, 10.0, 3.0), loopColour(v)), 0.03);
  // No loops.csv, or no accepted loop: no legend entry, as before loops existed.
  for (const bool keep_rejected : {false, true}) {
    if (keep_rejected) {
      r.loops = std::vector<io::LoopCsvRow>{loops()[2]};
    } else {
      r.loops.reset();
    }
    v = viz::buildRunView(r, viz::RunView::kTopDown, kW, kH);
    for (const auto& e : v.annotations.legend) EXPECT_EQ(e.label.find("loop"), std::string::npos);
  }
}

TEST(RenderLoopLayer, NearestPoseWithinTheStampGap) {
  const Trajectory t = loopingDrive();
  constexpr std::int64_t kGap = 200'000'000;
  EXPECT_EQ(viz::nearestPoseIndex(t, 0, kGap), 0U);
  EXPECT_EQ(viz::nearestPoseIndex(t, 5 * kSecond + 150'000'000, kGap), 5U);
  EXPECT_EQ(viz::nearestPoseIndex(t, 5 * kSecond + 850'000'000, kGap), 6U);
  EXPECT_EQ(viz::nearestPoseIndex(t, 134 * kSecond + kGap, kGap), 134U);
  EXPECT_EQ(viz::nearestPoseIndex(t, -kGap, kGap), 0U);
  EXPECT_FALSE(viz::nearestPoseIndex(t, 5 * kSecond + 500'000'000, kGap).has_value());
  EXPECT_FALSE(viz::nearestPoseIndex(t, -kGap - 1, kGap).has_value());
  EXPECT_FALSE(viz::nearestPoseIndex(t, 134 * kSecond + kGap + 1, kGap).has_value());
  EXPECT_FALSE(viz::nearestPoseIndex(Trajectory(), 0, kGap).has_value());
}

}  // namespace
}  // namespace gvio::test
