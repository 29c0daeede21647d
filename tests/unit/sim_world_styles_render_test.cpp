// sim/world styles rendered with the KITTI camera (EGL): every style gives images; the repetitive
// world's view repeats every period along a straight road (the street's does not); the
// sparse_texture world gives a tracker far fewer Shi-Tomasi corners than the street.
#include <gtest/gtest.h>

#include <iostream>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "odometry/feature_tracker.hpp"
#include "render/renderer.hpp"
#include "sim/kitti_convention.hpp"
#include "sim/world.hpp"
#include "sim_world_fixture.hpp"
#include "support/render_fixture.hpp"

namespace gvio::sim {
namespace {
using namespace world_fixture;  // NOLINT(google-build-using-namespace): test helpers

class SimWorldStylesRender : public test::SharedRendererTest {
 protected:
  static World build(const std::vector<Eigen::Vector3d>& route, WorldStyle style) {
    WorldOptions o;
    o.style = style;
    return buildWorld(route, o);
  }
  [[nodiscard]] cv::Mat render(const render::GpuScene& gpu, const Eigen::Isometry3d& T_w_c) const {
    const render::PinholeIntrinsics K = kittiIntrinsics();
    render::Framebuffer fb(K.width, K.height);
    return greyOf(renderer_->renderColor(gpu, render::pinholeCamera(K, T_w_c), fb));
  }
};

// Shi-Tomasi corners as the VIO's tracker selects them (its quality level and minimum distance),
// without its cap on the count: how much a tracker could find.
int trackerCorners(const cv::Mat& image) {
  const odometry::TrackerConfig tracker;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(image, corners, 0, tracker.quality_level, tracker.min_distance_px);
  return static_cast<int>(corners.size());
}

double correlation(const cv::Mat& a, const cv::Mat& b) {  // zero-mean normalised
  cv::Mat out;
  cv::matchTemplate(a, b, out, cv::TM_CCOEFF_NORMED);
  return static_cast<double>(out.at<float>(0, 0));
}

constexpr std::array<WorldStyle, 5> kAllStyles{WorldStyle::kStreet, WorldStyle::kOpenRoad,
                                               WorldStyle::kSparseTexture, WorldStyle::kRepetitive,
                                               WorldStyle::kVegetation};

// Three views per style along the two-turn street: not blank; corners printed for comparison.
// GVIO_SIM_DEBUG=1 writes them to /tmp.
TEST_F(SimWorldStylesRender, EveryStyleRenders) {
  const auto route = twoTurns();
  for (const WorldStyle style : kAllStyles) {
    const World world = build(route, style);
    const render::GpuScene gpu(world.scene);
    std::vector<int> corners;
    for (const double s : {60.0, 190.0, 330.0}) {
      const cv::Mat image = render(gpu, cameraAt(route, s));
      cv::Scalar mean, stddev;
      cv::meanStdDev(image, mean, stddev);
      EXPECT_GT(stddev[0], 10.0) << toString(style) << " at " << s;
      corners.push_back(trackerCorners(image));
      if (std::getenv("GVIO_SIM_DEBUG") != nullptr) {
        cv::imwrite("/tmp/sim_style_" + std::string(toString(style)) + "_" +
                        std::to_string(static_cast<int>(s)) + ".png",
                    image);
      }
    }
    std::cout << "[ " << toString(style) << " ] " << world.triangles
              << " triangles; tracker corners " << corners[0] << ", " << corners[1] << ", "
              << corners[2] << "\n";
  }
}

// On a straight 600 m road, views one period apart: the repetitive world's agree (zero-mean
// normalised correlation), the street's do not.
TEST_F(SimWorldStylesRender, RepetitiveViewRepeatsEveryPeriod) {
  const auto route = drive({{600.0, 0.0}});
  double repetitive_min = 1.0, street_max = -1.0;
  for (const WorldStyle style : {WorldStyle::kRepetitive, WorldStyle::kStreet}) {
    const World world = build(route, style);
    const render::GpuScene gpu(world.scene);
    for (int k = 0; k < 4; ++k) {
      const double s = 200.0 + 37.0 * k;  // an odd place in the period each time
      const double c = correlation(render(gpu, cameraAt(route, s)),
                                   render(gpu, cameraAt(route, s + kRepetitivePeriod_m)));
      std::cout << "[ " << toString(style) << " ] s " << s << " m: correlation with s + "
                << kRepetitivePeriod_m << " m " << c << "\n";
      if (style == WorldStyle::kRepetitive) repetitive_min = std::min(repetitive_min, c);
      if (style == WorldStyle::kStreet) street_max = std::max(street_max, c);
    }
  }
  EXPECT_GT(repetitive_min, 0.9);
  EXPECT_LT(street_max, 0.6);
}

// The same ten views of the two-turn street: the sparse_texture world has a fraction of the
// street's corners (the tracker's selection, uncapped).
TEST_F(SimWorldStylesRender, SparseTextureHasFewCorners) {
  const auto route = twoTurns();
  std::array<double, 2> mean{};
  const std::array<WorldStyle, 2> styles{WorldStyle::kStreet, WorldStyle::kSparseTexture};
  for (std::size_t i = 0; i < 2; ++i) {
    const World world = build(route, styles[i]);
    const render::GpuScene gpu(world.scene);
    int worst = 1 << 30, best = 0, sum = 0;
    for (int k = 0; k < 10; ++k) {
      const int n = trackerCorners(render(gpu, cameraAt(route, 20.0 + 36.0 * k)));
      worst = std::min(worst, n);
      best = std::max(best, n);
      sum += n;
    }
    mean[i] = sum / 10.0;
    std::cout << "[ " << toString(styles[i]) << " ] tracker corners per view: mean " << mean[i]
              << ", min " << worst << ", max " << best << "\n";
  }
  EXPECT_LT(mean[1], 0.3 * mean[0]);
}

}  // namespace
}  // namespace gvio::sim
