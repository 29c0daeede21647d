// The revisit-consistency plot (eval/revisits_plot): files, colours, thinning, bad input.
#include "eval/revisits_plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "odometry/error.hpp"
#include "support/fixtures.hpp"

namespace gvio::eval {
namespace {

namespace fs = std::filesystem;

// Pixels of `bgr` within `tol` (per channel) of the colour (r, g, b).
int countColour(const cv::Mat& bgr, int r, int g, int b, int tol) {
  int n = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      n += std::abs(p[2] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[0] - b) <= tol;
    }
  }
  return n;
}

// A 50 m circle driven twice (200 poses a lap); each pose of lap 1 pairs with the same place on
// lap 2, whose estimate is off by an error growing from 0 to 1 m round the lap.
struct TwoLaps {
  RevisitPlotData data;
  RevisitResult result;
};
TwoLaps twoLaps() {
  TwoLaps out;
  out.data.title = "revisits";
  constexpr std::size_t kLap = 200;
  for (std::size_t k = 0; k < 2 * kLap; ++k) {
    const double phi = 2.0 * std::numbers::pi * static_cast<double>(k % kLap) / kLap;
    const Eigen::Vector3d p(50.0 * std::cos(phi), 50.0 * std::sin(phi), 0.0);
    const double error = k < kLap ? 0.0 : static_cast<double>(k - kLap) / (kLap - 1);
    out.data.p_ref.push_back(p);
    out.data.p_est.push_back(p + Eigen::Vector3d(error, 0.0, 0.0));
  }
  std::vector<double> errors;
  for (std::size_t i = 0; i < kLap; ++i) {
    const double e = static_cast<double>(i) / (kLap - 1);
    out.result.pairs.push_back({i, i + kLap, 0, 0, 0.0, e});
    errors.push_back(e);
  }
  out.result.options.radius_m = 1.0;
  out.result.stats = RevisitStats{computeStats(errors), 0.95};
  return out;
}

class EvalRevisitsPlot : public ::testing::Test {
 protected:
  [[nodiscard]] std::string prefix(const std::string& name) const {
    return (dir_.path() / name).string();
  }
  test::TempDir dir_{"revisits_plot"};
};

TEST_F(EvalRevisitsPlot, WritesPngAndSvgColouredByError) {
  const TwoLaps laps = twoLaps();
  const auto paths = writeRevisitsPlot(laps.data, laps.result, prefix("run"));
  EXPECT_EQ(paths,
            (std::vector<std::string>{prefix("run_revisits.png"), prefix("run_revisits.svg")}));
  EXPECT_TRUE(test::readText(prefix("run_revisits.svg")).starts_with("<?xml"));
  const cv::Mat image = cv::imread(prefix("run_revisits.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1200);
  EXPECT_EQ(image.rows, 900);
  // The pairs themselves (left of the colour bar) span viridis from purple to yellow.
  const cv::Mat plot_area = image(cv::Rect(100, 92, 900, 700));
  EXPECT_GT(countColour(plot_area, 68, 1, 84, 20), 10);     // viridis(0)
  EXPECT_GT(countColour(plot_area, 33, 145, 140, 20), 10);  // viridis(0.5)
  EXPECT_GT(countColour(plot_area, 253, 231, 37, 20), 10);  // viridis(1)
}

TEST_F(EvalRevisitsPlot, NoPairsStillDrawsTheReference) {
  TwoLaps laps = twoLaps();
  laps.result.pairs.clear();
  laps.result.stats.reset();
  writeRevisitsPlot(laps.data, laps.result, prefix("none"));
  const cv::Mat image = cv::imread(prefix("none_revisits.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_GT(countColour(image(cv::Rect(100, 92, 900, 700)), 128, 128, 128, 10), 100);  // path
}

TEST_F(EvalRevisitsPlot, ManyPairsAreThinned) {
  TwoLaps laps = twoLaps();
  const std::vector<RevisitPair> lap_pairs = laps.result.pairs;
  laps.result.pairs.clear();
  for (int copy = 0; copy < 150; ++copy) {  // 30 000 pairs, above the 20 000 drawn
    laps.result.pairs.insert(laps.result.pairs.end(), lap_pairs.begin(), lap_pairs.end());
  }
  writeRevisitsPlot(laps.data, laps.result, prefix("many"));
  EXPECT_LT(fs::file_size(prefix("many_revisits.svg")), 20'000'000U);
  const cv::Mat image = cv::imread(prefix("many_revisits.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_GT(countColour(image(cv::Rect(100, 92, 900, 700)), 253, 231, 37, 20), 10);  // the worst
}

TEST_F(EvalRevisitsPlot, InconsistentInputThrows) {
  TwoLaps laps = twoLaps();
  laps.data.p_est.pop_back();
  EXPECT_THROW(writeRevisitsPlot(laps.data, laps.result, prefix("bad")), InvalidInput);
  laps = twoLaps();
  laps.result.pairs.push_back({0, 400, 0, 0, 0.0, 0.0});  // j past the 400 poses
  EXPECT_THROW(writeRevisitsPlot(laps.data, laps.result, prefix("bad")), InvalidInput);
  laps = twoLaps();
  laps.data.plane = {2, 2};
  EXPECT_THROW(writeRevisitsPlot(laps.data, laps.result, prefix("bad")), InvalidInput);
  EXPECT_THROW(writeRevisitsPlot(RevisitPlotData{}, RevisitResult{}, prefix("bad")), InvalidInput);
  EXPECT_FALSE(fs::exists(prefix("bad_revisits.png")));
}

}  // namespace
}  // namespace gvio::eval
