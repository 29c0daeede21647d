#include "eval/plots.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "io/input_error.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

namespace fs = std::filesystem;

// evo's statistics of d.error (population std, median of the sorted errors).
void fillStats(PlotData& d) {
  const auto n = static_cast<double>(d.error.size());
  double sum = 0.0, sq = 0.0;
  for (double e : d.error) sum += e, sq += e * e;
  d.stats.mean = sum / n;
  d.stats.rmse = std::sqrt(sq / n);
  d.stats.std = std::sqrt(sq / n - d.stats.mean * d.stats.mean);
  std::vector<double> sorted = d.error;
  std::sort(sorted.begin(), sorted.end());
  d.stats.median = 0.5 * (sorted[d.error.size() / 2 - 1] + sorted[d.error.size() / 2]);
  d.stats.min = sorted.front();
  d.stats.max = sorted.back();
  d.stats.n = d.error.size();
}

// A 50 m circle of 200 poses in the x-y plane, the estimate off by a sinusoidal radial error,
// one GNSS outage in the middle.
PlotData syntheticLoop() {
  PlotData d;
  d.title = "APE w.r.t. translation part (m), alignment: SE(3)";
  d.error_label = "APE (m)";
  constexpr int kPoses = 200;
  for (int i = 0; i < kPoses; ++i) {
    const double t = 0.5 * i, phi = 2.0 * std::numbers::pi * i / kPoses;
    const double err = 1.0 + 0.8 * std::sin(3.0 * phi);
    const Eigen::Vector3d dir(std::cos(phi), std::sin(phi), 0.0);
    d.t_s.push_back(t);
    d.p_ref.push_back(50.0 * dir + Eigen::Vector3d(0, 0, 0.5 * std::sin(phi)));
    d.p_est.push_back(d.p_ref.back() + err * dir);
    d.error.push_back(err);
  }
  fillStats(d);
  d.outages_s = {{30.0, 45.0}};
  d.plane = choosePlane(d.p_ref);
  return d;
}

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// True when some pixel is within `tol` (per channel) of the colour (r, g, b).
bool hasColour(const cv::Mat& bgr, int r, int g, int b, int tol) {
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      if (std::abs(p[2] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[0] - b) <= tol)
        return true;
    }
  }
  return false;
}

class PlotsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gvio_plots_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  [[nodiscard]] std::string prefix(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

TEST_F(PlotsTest, WritesSixFilesForALoop) {
  const std::vector<std::string> paths = writePlots(syntheticLoop(), prefix("loop"));
  const std::vector<std::string> expected = {
      prefix("loop_trajectory.png"), prefix("loop_trajectory.svg"), prefix("loop_error.png"),
      prefix("loop_error.svg"),      prefix("loop_axes.png"),       prefix("loop_axes.svg")};
  EXPECT_EQ(paths, expected);
  for (const std::string& p : paths) EXPECT_TRUE(fs::is_regular_file(p)) << p;
  // Nothing else (no temporaries) is left in the directory.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 6);
}

TEST_F(PlotsTest, PngsAreFullSizeAndNotBlank) {
  writePlots(syntheticLoop(), prefix("loop"));
  for (const char* name : {"loop_trajectory.png", "loop_error.png", "loop_axes.png"}) {
    const cv::Mat image = cv::imread(prefix(name), cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << name;
    EXPECT_EQ(image.cols, 1200) << name;
    EXPECT_EQ(image.rows, 900) << name;
    cv::Scalar mean, stddev;
    cv::meanStdDev(image, mean, stddev);
    EXPECT_GT(stddev[0], 15.0) << name;
  }
}

TEST_F(PlotsTest, TrajectoryIsColouredWithViridis) {
  writePlots(syntheticLoop(), prefix("loop"));
  const cv::Mat image = cv::imread(prefix("loop_trajectory.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_TRUE(hasColour(image, 68, 1, 84, 12));     // viridis(0), dark purple
  EXPECT_TRUE(hasColour(image, 33, 145, 140, 12));  // viridis(0.5), teal
  EXPECT_TRUE(hasColour(image, 253, 231, 37, 12));  // viridis(1), yellow
  // The estimate itself (not only the colour bar) is coloured: look left of the colour bar.
  const cv::Mat plot_area = image(cv::Rect(100, 92, 900, 700));
  EXPECT_TRUE(hasColour(plot_area, 33, 145, 140, 20));
}

TEST_F(PlotsTest, SvgsAreSvgDocuments) {
  writePlots(syntheticLoop(), prefix("loop"));
  for (const char* name : {"loop_trajectory.svg", "loop_error.svg", "loop_axes.svg"}) {
    const std::string svg = readAll(prefix(name));
    EXPECT_TRUE(svg.starts_with("<?xml")) << name;
    EXPECT_NE(svg.find("<svg"), std::string::npos) << name;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << name;
  }
}

TEST(PlotsChoosePlane, PicksTheTwoLargestExtents) {
  std::vector<Eigen::Vector3d> xz;
  for (int i = 0; i < 50; ++i) {
    xz.emplace_back(10.0 * std::cos(0.1 * i), 0.01 * i, 5.0 * std::sin(0.1 * i));
  }
  EXPECT_EQ(choosePlane(xz), (std::array<int, 2>{0, 2}));
  std::vector<Eigen::Vector3d> yz = {{0, 0, 0}, {0.1, 3, 0}, {0, 1, 7}};
  EXPECT_EQ(choosePlane(yz), (std::array<int, 2>{1, 2}));
  EXPECT_EQ(choosePlane({}), (std::array<int, 2>{0, 1}));
}

TEST_F(PlotsTest, SinglePoseDoesNotThrow) {
  PlotData d;
  d.title = "single";
  d.error_label = "APE (m)";
  d.t_s = {0.0};
  d.p_ref = {Eigen::Vector3d(1000.0, 2000.0, 3.0)};
  d.p_est = {Eigen::Vector3d(1000.0, 2000.0, 3.0)};
  d.error = {0.0};
  d.outages_s = {{-5.0, 5.0}};
  EXPECT_EQ(writePlots(d, prefix("single")).size(), 6U);
  EXPECT_FALSE(cv::imread(prefix("single_trajectory.png")).empty());
}

TEST_F(PlotsTest, ConstantErrorAndStraightLineDoNotThrow) {
  PlotData d = syntheticLoop();
  std::fill(d.error.begin(), d.error.end(), 0.25);
  for (std::size_t i = 0; i < d.p_ref.size(); ++i) {
    d.p_ref[i] = Eigen::Vector3d(static_cast<double>(i), 0.0, 0.0);  // zero extent in y and z
    d.p_est[i] = d.p_ref[i];
  }
  d.stats = {};
  d.outages_s = {{1e6, 2e6}};  // outside the time range
  EXPECT_EQ(writePlots(d, prefix("flat")).size(), 6U);
}

TEST_F(PlotsTest, UnwritablePrefixNamesTheFile) {
  const std::string bad = prefix("missing_dir/run");
  try {
    writePlots(syntheticLoop(), bad);
    FAIL() << "expected io::InputError";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + "_trajectory.png"), std::string::npos) << e.what();
  }
}

TEST_F(PlotsTest, InconsistentOrEmptyInputThrows) {
  PlotData d = syntheticLoop();
  d.error.pop_back();
  EXPECT_THROW(writePlots(d, prefix("bad")), InvalidInput);
  d = syntheticLoop();
  d.p_est.pop_back();
  EXPECT_THROW(writePlots(d, prefix("bad")), InvalidInput);
  d = syntheticLoop();
  d.plane = {1, 1};
  EXPECT_THROW(writePlots(d, prefix("bad")), InvalidInput);
  EXPECT_THROW(writePlots(PlotData{}, prefix("bad")), InvalidInput);
  EXPECT_FALSE(fs::exists(prefix("bad_trajectory.png")));
}

}  // namespace
}  // namespace gvio::eval
