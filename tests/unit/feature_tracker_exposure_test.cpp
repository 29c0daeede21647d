// Exposure changes in the front end (odometry/photometric_gain.hpp, TrackerConfig::
// gain_threshold): the gain of a matched image pair is measured from its patches, and frames
// whose exposure stepped (or a right camera exposed differently) are tracked against the image
// with the gain removed. Without an exposure change the tracker's output is exactly that of the
// tracker without the correction.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "odometry/feature_tracker.hpp"
#include "odometry/photometric_gain.hpp"
#include "support/fixtures.hpp"
#include "support/tracker_drive.hpp"
#include "support/true_motion.hpp"

namespace gvio::test {
namespace {
using odometry::FeatureTracker;
using odometry::TrackedFrame;
using odometry::TrackerConfig;

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// Blurred noise (grey values about 60-190) and a grid of points on it.
cv::Mat texture(int rows, int cols) {
  cv::Mat noise(rows, cols, CV_32F), blurred, out;
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, blurred, cv::Size(0, 0), 2.0);
  cv::normalize(blurred, blurred, 60.0, 190.0, cv::NORM_MINMAX);
  blurred.convertTo(out, CV_8U);
  return out;
}

std::vector<cv::Point2f> grid(int rows, int cols, int step) {
  std::vector<cv::Point2f> px;
  for (int y = step; y < rows - step; y += step)
    for (int x = step; x < cols - step; x += step)
      px.emplace_back(static_cast<float>(x) + 0.3F, static_cast<float>(y) + 0.6F);
  return px;
}

TEST(PhotometricGain, TheMedianPatchRatioIsTheImagesGain) {
  const cv::Mat a = texture(200, 300);
  const std::vector<cv::Point2f> px = grid(200, 300, 20);
  const std::vector<bool> all(px.size(), true);
  for (const double gain : {0.8, 1.0, 1.07, 1.25}) {
    cv::Mat b;
    a.convertTo(b, CV_8U, gain);
    const std::optional<double> g = odometry::medianPatchGain(a, b, px, px, all, 4, 10);
    ASSERT_TRUE(g.has_value());
    EXPECT_NEAR(*g, gain, 0.004) << "gain " << gain;
    // Removing it gives the first image back, to the rounding of the two conversions.
    cv::Mat back, diff;
    odometry::removeGain(b, *g, back);
    cv::absdiff(back, a, diff);
    EXPECT_LE(cv::norm(diff, cv::NORM_INF), 2.0) << "gain " << gain;
  }
}

// A patch's mean is that of the bilinear patch at the sub-pixel position (what cv::getRectSubPix
// samples): one point from a uniform grey 100 into a texture has the gain mean / 100.
TEST(PhotometricGain, PatchesAreSampledAtTheSubPixelPosition) {
  const cv::Mat grey(100, 120, CV_8U, cv::Scalar(100)), tex = texture(100, 120);
  for (const cv::Point2f p : {cv::Point2f(50.0F, 40.0F), cv::Point2f(50.25F, 40.5F),
                              cv::Point2f(61.9F, 33.3F), cv::Point2f(10.01F, 88.99F)}) {
    cv::Mat patch;
    cv::getRectSubPix(tex, cv::Size(9, 9), p, patch, CV_32F);
    const std::optional<double> g = odometry::medianPatchGain(grey, tex, {p}, {p}, {true}, 4, 1);
    ASSERT_TRUE(g.has_value());
    EXPECT_NEAR(*g, cv::mean(patch)[0] / 100.0, 1e-5) << p;
  }
}

TEST(PhotometricGain, TooFewPatchesGiveNoGain) {
  const cv::Mat a = texture(100, 100);
  std::vector<cv::Point2f> px = {{50.0F, 50.0F}, {30.0F, 30.0F}, {2.0F, 2.0F}, {99.0F, 50.0F}};
  const std::vector<bool> all(px.size(), true);
  // Two patches inside the image (the last two leave it), ten needed.
  EXPECT_FALSE(odometry::medianPatchGain(a, a, px, px, all, 4, 10).has_value());
  ASSERT_TRUE(odometry::medianPatchGain(a, a, px, px, all, 4, 2).has_value());
  EXPECT_DOUBLE_EQ(*odometry::medianPatchGain(a, a, px, px, all, 4, 2), 1.0);
  // Unmatched points do not count.
  EXPECT_FALSE(
      odometry::medianPatchGain(a, a, px, px, {true, false, true, true}, 4, 2).has_value());
  // A black first image has no ratio.
  const cv::Mat black = cv::Mat::zeros(100, 100, CV_8U);
  EXPECT_FALSE(odometry::medianPatchGain(black, a, px, px, all, 4, 1).has_value());
}

// The 3 s simulated drive of the tracker tests, with exposure steps put into its images.
class FeatureTrackerExposureTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    StereoDrive drive = trackerTestDrive();
    dataset_ = std::make_unique<io::Dataset>(std::move(drive.dataset));
    left_ = std::move(drive.left);
    right_ = std::move(drive.right);
  }
  static void TearDownTestSuite() {
    left_.clear();
    right_.clear();
    dataset_.reset();
  }
  void SetUp() override { ASSERT_EQ(left_.size(), 31u) << "the simulation failed"; }

  // Frame k's images times left_gain(k) and right_gain(k), tracked with `config`.
  template <class LeftGain, class RightGain>
  static std::vector<TrackedFrame> track(const TrackerConfig& config, LeftGain left_gain,
                                         RightGain right_gain) {
    FeatureTracker tracker(config);
    std::vector<TrackedFrame> out;
    for (std::size_t k = 0; k < left_.size(); ++k) {
      cv::Mat l, r;
      left_[k].convertTo(l, CV_8U, left_gain(k));
      right_[k].convertTo(r, CV_8U, right_gain(k));
      out.push_back(tracker.track(dataset_->frames[k].t_ns, l, r));
    }
    return out;
  }

  static std::unique_ptr<io::Dataset> dataset_;
  static std::vector<cv::Mat> left_, right_;
};
std::unique_ptr<io::Dataset> FeatureTrackerExposureTest::dataset_;
std::vector<cv::Mat> FeatureTrackerExposureTest::left_, FeatureTrackerExposureTest::right_;

TrackerConfig withGainThreshold(double threshold) {
  TrackerConfig c;
  c.gain_threshold = threshold;
  return c;
}

const auto kSame = [](std::size_t) { return 1.0; };

TEST_F(FeatureTrackerExposureTest, WithoutExposureChangesTheOutputIsUnchanged) {
  const auto with = track(TrackerConfig{}, kSame, kSame);
  const auto without = track(withGainThreshold(0.0), kSame, kSame);
  ASSERT_EQ(with.size(), without.size());
  for (std::size_t k = 0; k < with.size(); ++k) {
    EXPECT_EQ(with[k].stats.exposure_gain, 1.0) << "frame " << k;
    EXPECT_EQ(with[k].stats.stereo_gain, 1.0) << "frame " << k;
    ASSERT_EQ(with[k].features.size(), without[k].features.size()) << "frame " << k;
    for (std::size_t i = 0; i < with[k].features.size(); ++i) {
      EXPECT_EQ(with[k].features[i].id, without[k].features[i].id);
      EXPECT_EQ(with[k].features[i].px_left, without[k].features[i].px_left);
      EXPECT_EQ(with[k].features[i].px_right, without[k].features[i].px_right);
    }
  }
}

// Every other frame 15 % brighter (an auto exposure hunting): KLT takes part of the brightness
// step for motion. With the gain removed the tracks agree with the true motion as well as on the
// unchanged images.
TEST_F(FeatureTrackerExposureTest, ExposureStepsBetweenFramesAreRemoved) {
  constexpr double kStep = 1.15;
  const auto stepped = [](std::size_t k) { return k % 2 == 1 ? kStep : 1.0; };
  const auto plain = track(TrackerConfig{}, kSame, kSame);
  const auto corrected = track(TrackerConfig{}, stepped, stepped);
  const auto uncorrected = track(withGainThreshold(0.0), stepped, stepped);
  for (std::size_t k = 1; k < corrected.size(); ++k) {
    const double expected = k % 2 == 1 ? kStep : 1.0 / kStep;
    EXPECT_NEAR(corrected[k].stats.exposure_gain, expected, 0.01) << "frame " << k;
    EXPECT_EQ(corrected[k].stats.stereo_gain, 1.0) << "frame " << k;
  }
  const auto report = [&](const char* name, const std::vector<TrackedFrame>& tracked) {
    const std::vector<double> e = trueMotionErrors(*dataset_, tracked);
    std::size_t tracks = 0;
    for (const auto& f : tracked) tracks += static_cast<std::size_t>(f.stats.tracked);
    std::cout << "[ exposure ] " << name << ": true-motion error median " << quantile(e, 0.5)
              << " px, p90 " << quantile(e, 0.9) << " px over " << e.size() << " stereo tracks, "
              << tracks << " tracks carried\n";
    return std::pair{quantile(e, 0.9), tracks};
  };
  const auto [p90_plain, tracks_plain] = report("unchanged images", plain);
  const auto [p90_corrected, tracks_corrected] = report("steps, gain removed", corrected);
  const auto [p90_uncorrected, tracks_uncorrected] = report("steps, as they are", uncorrected);
  EXPECT_LT(p90_corrected, p90_uncorrected);
  EXPECT_LT(p90_corrected, 1.25 * p90_plain);
  EXPECT_GT(static_cast<double>(tracks_corrected), 0.97 * static_cast<double>(tracks_plain));
  (void)tracks_uncorrected;
}

// A right camera exposed 20 % brighter than the left one: its matches are made against the right
// image with that gain removed, and the rig's disparities agree with those of equal exposures.
TEST_F(FeatureTrackerExposureTest, ARightCameraExposedDifferentlyIsMatched) {
  const auto brighter = [](std::size_t) { return 1.2; };
  const auto plain = track(TrackerConfig{}, kSame, kSame);
  const auto corrected = track(TrackerConfig{}, kSame, brighter);
  const auto uncorrected = track(withGainThreshold(0.0), kSame, brighter);
  for (const auto& f : corrected) EXPECT_NEAR(f.stats.stereo_gain, 1.2, 0.01);
  // Disparity differences from the equal-exposure run, over features matched in both.
  const auto disparityErrors = [&](const std::vector<TrackedFrame>& tracked) {
    std::vector<double> e;
    for (std::size_t k = 0; k < tracked.size(); ++k) {
      for (const auto& a : tracked[k].features) {
        for (const auto& b : plain[k].features) {
          if (a.id != b.id || !a.has_right || !b.has_right) continue;
          e.push_back(
              std::abs((a.px_left.x() - a.px_right.x()) - (b.px_left.x() - b.px_right.x())));
        }
      }
    }
    return e;
  };
  const std::vector<double> e_corrected = disparityErrors(corrected);
  const std::vector<double> e_uncorrected = disparityErrors(uncorrected);
  int matches_plain = 0, matches_corrected = 0, matches_uncorrected = 0;
  for (std::size_t k = 0; k < plain.size(); ++k) {
    matches_plain += plain[k].stats.stereo_matches;
    matches_corrected += corrected[k].stats.stereo_matches;
    matches_uncorrected += uncorrected[k].stats.stereo_matches;
  }
  std::cout << "[ exposure ] stereo matches: " << matches_plain << " equal exposures, "
            << matches_corrected << " right +20 % gain removed, " << matches_uncorrected
            << " as it is; disparity change p90 " << quantile(e_corrected, 0.9) << " / "
            << quantile(e_uncorrected, 0.9) << " px\n";
  ASSERT_GT(e_corrected.size(), 500u);
  EXPECT_LT(quantile(e_corrected, 0.9), quantile(e_uncorrected, 0.9));
  EXPECT_LT(quantile(e_corrected, 0.9), 0.2);
  EXPECT_GT(matches_corrected, matches_uncorrected);
}

// End to end: a drive whose exposure swings by 30 % every 2 s and whose right camera is 25 %
// brighter. Every frame's stereo pair and most frames' steps are corrected, and the run is about as
// accurate as the same drive with the corrections off is not.
TEST(FeatureTrackerExposureRun, ADriveWithExposureChangesIsCorrected) {
  const std::filesystem::path sim = cachedSimulation(fmt::format(
      "--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 7 --set sim.exposure_change=true "
      "--set sim.exposure_amplitude=0.3 --set sim.exposure_period_s=2 "
      "--set sim.right_camera_gain=1.25",
      GVIO_SOURCE_DIR));
  TempDir dir("exposure_run");
  const auto run = [&](const std::string& name, const std::string& extra) {
    const CommandResult r = runGvio(fmt::format(
        "run --dataset {} --gnss off --set map.enabled=false --set loops.enabled=false {} --out {} "
        "--no-progress -q",
        quoted(sim), extra, quoted(dir.path() / name)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(readText(dir.path() / name / "report.json"));
  };
  const auto on = run("on", "");
  const auto off = run("off", "--set vio.tracker.gain_threshold=0");
  const int frames = on["counts"]["frames"].get<int>();
  const double ape_on = on["evaluation"]["ape_se3"]["rmse"].get<double>();
  const double ape_off = off["evaluation"]["ape_se3"]["rmse"].get<double>();
  std::cout << "[ exposure ] 8 s drive: " << on["counts"]["exposure_corrected_frames"]
            << " frames' steps and " << on["counts"]["stereo_gain_corrected_frames"] << " of "
            << frames << " stereo pairs corrected; APE " << ape_on << " m (" << ape_off
            << " m uncorrected)\n";
  EXPECT_EQ(on["counts"]["stereo_gain_corrected_frames"].get<int>(), frames);
  EXPECT_GT(on["counts"]["exposure_corrected_frames"].get<int>(), frames / 2);
  EXPECT_EQ(off["counts"]["exposure_corrected_frames"].get<int>(), 0);
  EXPECT_EQ(off["counts"]["stereo_gain_corrected_frames"].get<int>(), 0);
  EXPECT_LT(ape_on, ape_off);
}

// The real EuRoC V1_01 clip: its right camera's images are about 15 % darker than the left
// one's (an independently exposed rig), and every pair is matched with that gain removed.
TEST(FeatureTrackerExposureEuroc, ARealRigsRightCameraIsCorrected) {
  const std::vector<StereoPair> pairs = eurocClipRectified();
  if (pairs.empty()) GTEST_SKIP() << "shared data absent: euroc_v101_micro";
  FeatureTracker corrected{TrackerConfig{}}, uncorrected{withGainThreshold(0.0)};
  std::vector<double> gains;
  int matches_corrected = 0, matches_uncorrected = 0;
  for (const StereoPair& p : pairs) {
    const TrackedFrame a = corrected.track(p.t_ns, p.left, p.right);
    const TrackedFrame b = uncorrected.track(p.t_ns, p.left, p.right);
    gains.push_back(a.stats.stereo_gain);
    matches_corrected += a.stats.stereo_matches;
    matches_uncorrected += b.stats.stereo_matches;
  }
  std::cout << "[ exposure ] EuRoC: right / left gain " << quantile(gains, 0.1) << " - "
            << quantile(gains, 0.9) << " (median " << quantile(gains, 0.5) << "); stereo matches "
            << matches_corrected << " corrected, " << matches_uncorrected << " not\n";
  EXPECT_LT(quantile(gains, 0.9), 0.98);
  EXPECT_GT(quantile(gains, 0.1), 0.8);
  // 6055 against 1417 (2026-11-30).
  EXPECT_GT(matches_corrected, 2 * matches_uncorrected);
}

}  // namespace
}  // namespace gvio::test
