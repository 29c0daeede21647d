// The visual front end on a simulated KITTI-like drive: tracks persist and agree with the true
// camera motion, stereo matches lie on the epipolar line, corrupted and black frames are handled,
// bad configurations and images are refused, and the output is deterministic.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <set>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"
#include "odometry/feature_tracker.hpp"
#include "support/fixtures.hpp"
#include "support/tracker_drive.hpp"
#include "support/true_motion.hpp"

namespace gvio::test {
namespace {
using odometry::Feature;
using odometry::FeatureTracker;
using odometry::TrackedFrame;
using odometry::TrackerConfig;
using testing::HasSubstr;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::map<std::uint64_t, Feature> byId(const TrackedFrame& frame) {
  std::map<std::uint64_t, Feature> m;
  for (const Feature& f : frame.features) m[f.id] = f;
  return m;
}

class FeatureTrackerTest : public ::testing::Test {
 protected:
  // One 3 s simulated drive (31 stereo frames) and the default tracker's output on it.
  static void SetUpTestSuite() {
    StereoDrive drive = trackerTestDrive();
    dataset_ = std::make_unique<io::Dataset>(std::move(drive.dataset));
    ASSERT_EQ(dataset_->cameras.size(), 2u);
    ASSERT_EQ(dataset_->frames.size(), 31u);
    left_ = std::move(drive.left);
    right_ = std::move(drive.right);
    FeatureTracker tracker{TrackerConfig{}};
    for (std::size_t k = 0; k < left_.size(); ++k)
      tracked_.push_back(tracker.track(dataset_->frames[k].t_ns, left_[k], right_[k]));
  }
  void SetUp() override {
    ASSERT_TRUE(dataset_) << "the simulation failed";
    ASSERT_EQ(tracked_.size(), 31u);
  }
  static void TearDownTestSuite() {
    tracked_.clear();
    left_.clear();
    right_.clear();
    dataset_.reset();
  }

  static std::unique_ptr<io::Dataset> dataset_;
  static std::vector<cv::Mat> left_, right_;
  static std::vector<TrackedFrame> tracked_;
};
std::unique_ptr<io::Dataset> FeatureTrackerTest::dataset_;
std::vector<cv::Mat> FeatureTrackerTest::left_, FeatureTrackerTest::right_;
std::vector<TrackedFrame> FeatureTrackerTest::tracked_;

TEST_F(FeatureTrackerTest, TracksPersistWithUniqueIds) {
  ASSERT_EQ(tracked_.size(), 31u);
  std::vector<double> median_length, mean_length;
  int min_features = 1 << 30, min_tracked = 1 << 30;
  double sum_new = 0, sum_fb = 0, sum_ransac = 0;
  for (std::size_t k = 0; k < tracked_.size(); ++k) {
    const TrackedFrame& f = tracked_[k];
    EXPECT_EQ(f.t_ns, dataset_->frames[k].t_ns);
    EXPECT_LE(f.features.size(), 200u);
    EXPECT_EQ(f.stats.tracked + f.stats.new_features, static_cast<int>(f.features.size()));
    std::set<std::uint64_t> ids;
    std::vector<double> lengths;
    for (const Feature& feat : f.features) {
      EXPECT_TRUE(ids.insert(feat.id).second) << "duplicate id " << feat.id << " in frame " << k;
      lengths.push_back(feat.track_length);
    }
    median_length.push_back(median(lengths));
    mean_length.push_back(std::accumulate(lengths.begin(), lengths.end(), 0.0) /
                          static_cast<double>(std::max<std::size_t>(lengths.size(), 1)));
    if (k == 0) {
      EXPECT_EQ(f.stats.tracked, 0);
      continue;
    }
    min_features = std::min(min_features, static_cast<int>(f.features.size()));
    min_tracked = std::min(min_tracked, f.stats.tracked);
    sum_new += f.stats.new_features;
    sum_fb += f.stats.rejected_fb;
    sum_ransac += f.stats.rejected_ransac;
    // A feature seen before was in the previous frame under the same id, one frame shorter.
    const auto prev = byId(tracked_[k - 1]);
    int carried = 0;
    for (const Feature& feat : f.features) {
      if (feat.track_length == 1) {
        EXPECT_EQ(prev.count(feat.id), 0u) << "new feature reuses id " << feat.id;
        continue;
      }
      ++carried;
      const auto it = prev.find(feat.id);
      ASSERT_NE(it, prev.end()) << "id " << feat.id << " in frame " << k << " came from nowhere";
      EXPECT_EQ(feat.track_length, it->second.track_length + 1);
    }
    EXPECT_EQ(carried, f.stats.tracked);
  }
  std::cout << "[ tracker ] min features/frame " << min_features << ", median track length at "
            << "frames 1/5/10/20/30: " << median_length[1] << "/" << median_length[5] << "/"
            << median_length[10] << "/" << median_length[20] << "/" << median_length[30]
            << " (mean " << mean_length[5] << " at 5, " << mean_length[30]
            << " at 30); per frame: min tracked " << min_tracked << ", mean new " << sum_new / 30
            << ", rejected fb " << sum_fb / 30 << ", ransac " << sum_ransac / 30 << "\n";
  EXPECT_GE(min_features, 150);
  // Ids persist: past the start the typical feature has lived for several frames, and the
  // population keeps ageing (features near the focus of expansion live for the whole drive).
  for (std::size_t k = 5; k < median_length.size(); ++k) EXPECT_GE(median_length[k], 4.0) << k;
  EXPECT_GT(mean_length[30], mean_length[5] + 1.0);
}

TEST_F(FeatureTrackerTest, StereoMatchesLieOnTheEpipolarLine) {
  std::vector<double> vertical;
  double min_fraction = 1.0;
  for (const TrackedFrame& f : tracked_) {
    int matched = 0;
    for (const Feature& feat : f.features) {
      if (!feat.has_right) continue;
      ++matched;
      vertical.push_back(std::abs(feat.px_right.y() - feat.px_left.y()));
      EXPECT_LE(feat.px_right.x(), feat.px_left.x());  // non-negative disparity
    }
    EXPECT_EQ(matched, f.stats.stereo_matches);
    EXPECT_EQ(f.stats.stereo_matches + f.stats.rejected_stereo,
              static_cast<int>(f.features.size()));
    min_fraction = std::min(min_fraction,
                            static_cast<double>(matched) / static_cast<double>(f.features.size()));
  }
  std::cout << "[ tracker ] stereo: min matched fraction " << min_fraction << ", median |dy| "
            << median(vertical) << " px\n";
  EXPECT_GE(min_fraction, 0.6);
  EXPECT_LT(median(vertical), 0.3);
}

// A rig whose rectification leaves the right image 1.2 px low offsets every match alike: the row
// check follows the frame's median offset and keeps about as many matches as on the true rig.
TEST_F(FeatureTrackerTest, TheRowCheckFollowsTheRigsRowOffset) {
  constexpr double kShiftPx = 1.2;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, 1, kShiftPx);
  FeatureTracker tracker{TrackerConfig{}};
  double min_fraction = 1.0, min_ratio = 1e9;
  for (std::size_t k = 0; k < left_.size(); ++k) {
    cv::Mat low;
    cv::warpAffine(right_[k], low, shift, right_[k].size(), cv::INTER_LINEAR,
                   cv::BORDER_REFLECT_101);
    const TrackedFrame f = tracker.track(dataset_->frames[k].t_ns, left_[k], low);
    EXPECT_NEAR(f.stats.stereo_row_offset_px, kShiftPx, 0.1) << k;
    EXPECT_NEAR(tracked_[k].stats.stereo_row_offset_px, 0.0, 0.1) << k;
    min_fraction = std::min(min_fraction, static_cast<double>(f.stats.stereo_matches) /
                                              static_cast<double>(f.features.size()));
    min_ratio = std::min(min_ratio, static_cast<double>(f.stats.stereo_matches) /
                                        static_cast<double>(tracked_[k].stats.stereo_matches));
  }
  std::cout << "[ tracker ] right image 1.2 px low: min matched fraction " << min_fraction
            << ", min matches against the true rig's " << min_ratio << "\n";
  EXPECT_GE(min_fraction, 0.6);
  EXPECT_GE(min_ratio, 0.8);
}

// Stereo features of frame k are lifted to 3-D with the true baseline, moved with the true camera
// motion to frame k + 1 and projected: they must land where the tracker followed them.
TEST_F(FeatureTrackerTest, TracksAgreeWithTheTrueMotion) {
  const std::vector<double> errors = trueMotionErrors(*dataset_, tracked_);
  ASSERT_GT(errors.size(), 1000u);
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const double p90 = sorted[sorted.size() * 9 / 10];
  std::cout << "[ tracker ] true-motion reprojection: median " << median(errors) << " px, p90 "
            << p90 << " px over " << errors.size() << " tracks\n";
  EXPECT_LT(median(errors), 0.5);
  EXPECT_LT(p90, 2.0);
}

// Image velocities (for the camera-IMU time offset): a tracked feature's is its displacement
// since the previous frame over the stamps' difference, left and right (the right one along x from
// the change of disparity, along y the left one's: rectified rows); a new feature's is zero.
// A feature's velocity is its backward difference since the previous frame, carried to this
// frame with the difference before it (constant image acceleration), once it has one; the right
// pixel's is the left one's less the rate of disparity, estimated the same way.
TEST_F(FeatureTrackerTest, VelocitiesAreTheBackwardDifferencesCarriedToTheFrame) {
  int checked = 0, extrapolated = 0, checked_right = 0, fresh = 0;
  for (std::size_t k = 1; k < tracked_.size(); ++k) {
    const double dt_s = 1e-9 * static_cast<double>(tracked_[k].t_ns - tracked_[k - 1].t_ns);
    const double dt_prev_s =
        k >= 2 ? 1e-9 * static_cast<double>(tracked_[k - 1].t_ns - tracked_[k - 2].t_ns) : 0.0;
    const double w = dt_s / (dt_s + dt_prev_s);
    const auto previous = byId(tracked_[k - 1]);
    const auto before = k >= 2 ? byId(tracked_[k - 2]) : decltype(previous){};
    for (const Feature& f : tracked_[k].features) {
      const auto it = previous.find(f.id);
      if (it == previous.end()) {
        EXPECT_TRUE(f.velocity_pxps.isZero(0.0));
        ++fresh;
        continue;
      }
      const Feature& p = it->second;
      const auto bt = before.find(f.id);
      const Eigen::Vector2d step = (f.px_left - p.px_left) / dt_s;
      Eigen::Vector2d expected = step;
      if (bt != before.end()) {
        expected += (step - (p.px_left - bt->second.px_left) / dt_prev_s) * w;
        ++extrapolated;
      }
      EXPECT_LT((f.velocity_pxps - expected).norm(), 1e-3 * std::max(1.0, expected.norm()));
      ++checked;
      if (f.has_right && p.has_right) {
        const auto disparity = [](const Feature& x) { return x.px_left.x() - x.px_right.x(); };
        double rate = (disparity(f) - disparity(p)) / dt_s;
        if (bt != before.end() && bt->second.has_right) {
          rate += (rate - (disparity(p) - disparity(bt->second)) / dt_prev_s) * w;
        }
        EXPECT_NEAR(f.velocity_right_pxps.x(), f.velocity_pxps.x() - rate,
                    1e-3 * std::max(1.0, std::abs(rate)));
        EXPECT_EQ(f.velocity_right_pxps.y(), f.velocity_pxps.y());
        ++checked_right;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_GT(extrapolated, 1000);
  EXPECT_GT(checked_right, 1000);
  EXPECT_GT(fresh, 0);
}

// Frame k + 1 with a 200 x 150 region (around the focus of expansion) replaced by the content 40 px
// right and 40 px down: the tracks that started in the region must be rejected, the others must
// survive as on the clean frame. KLT may well find the displaced content (the forward-backward
// check then passes), so rejection rests on the epipolar constraint, which cannot see an error
// along the epipolar line: a few tracks next to the focus of expansion, where every direction is
// nearly along it, may survive. (A horizontal shift would be a poor probe for the same reason:
// the epipolar lines there are nearly horizontal.)
TEST_F(FeatureTrackerTest, RejectsTracksIntoAPastedPatch) {
  constexpr std::size_t k = 10;
  const cv::Rect region(500, 150, 200, 150);
  cv::Mat corrupted = left_[k + 1].clone();
  left_[k + 1](region + cv::Point(40, 40)).copyTo(corrupted(region));

  FeatureTracker clean{TrackerConfig{}}, dirty{TrackerConfig{}};
  TrackedFrame before;
  for (std::size_t i = 0; i <= k; ++i) {
    before = clean.track(dataset_->frames[i].t_ns, left_[i], right_[i]);
    dirty.track(dataset_->frames[i].t_ns, left_[i], right_[i]);
  }
  const std::int64_t t = dataset_->frames[k + 1].t_ns;
  const TrackedFrame a = clean.track(t, left_[k + 1], right_[k + 1]);
  const TrackedFrame b = dirty.track(t, corrupted, right_[k + 1]);
  const auto a_ids = byId(a), b_ids = byId(b);

  const cv::Rect inner(region.x + 12, region.y + 12, region.width - 24, region.height - 24);
  const cv::Rect outer(region.x - 60, region.y - 30, region.width + 120, region.height + 60);
  int in_region = 0, in_region_kept = 0, outside_clean = 0, outside_kept = 0, wrong = 0;
  for (const Feature& f : before.features) {
    const cv::Point2f p(static_cast<float>(f.px_left.x()), static_cast<float>(f.px_left.y()));
    const auto ib = b_ids.find(f.id);
    const auto ia = a_ids.find(f.id);
    const bool kept = ib != b_ids.end() && ib->second.track_length > 1;
    if (kept && ia != a_ids.end() && (ib->second.px_left - ia->second.px_left).norm() > 1.0)
      ++wrong;
    if (inner.contains(p)) {
      ++in_region;
      in_region_kept += kept ? 1 : 0;
    } else if (!outer.contains(p) && ia != a_ids.end() && ia->second.track_length > 1) {
      ++outside_clean;
      outside_kept += kept ? 1 : 0;
    }
  }
  std::cout << "[ tracker ] pasted patch: " << in_region_kept << "/" << in_region
            << " tracks kept inside, " << outside_kept << "/" << outside_clean
            << " outside; rejected fb " << b.stats.rejected_fb << " (clean " << a.stats.rejected_fb
            << "), ransac " << b.stats.rejected_ransac << " (clean " << a.stats.rejected_ransac
            << "); " << wrong << " surviving tracks differ from the clean ones\n";
  ASSERT_GE(in_region, 5);
  EXPECT_GT(b.stats.rejected_fb + b.stats.rejected_ransac,
            a.stats.rejected_fb + a.stats.rejected_ransac);
  EXPECT_LE(in_region_kept, in_region / 5);
  EXPECT_LE(wrong, in_region / 5);
  EXPECT_GE(outside_kept, outside_clean * 9 / 10);
}

TEST_F(FeatureTrackerTest, BlackFrameGivesNoFeaturesAndResetRecovers) {
  FeatureTracker tracker{TrackerConfig{}};
  std::uint64_t max_id = 0;
  for (std::size_t k = 0; k < 5; ++k) {
    for (const Feature& f : tracker.track(dataset_->frames[k].t_ns, left_[k], right_[k]).features)
      max_id = std::max(max_id, f.id);
  }
  const cv::Mat black = cv::Mat::zeros(left_[0].size(), CV_8UC1);
  TrackedFrame dark;
  ASSERT_NO_THROW(dark = tracker.track(dataset_->frames[5].t_ns, black, black));
  EXPECT_TRUE(dark.features.empty());
  EXPECT_EQ(dark.stats.tracked, 0);
  EXPECT_EQ(dark.stats.new_features, 0);
  // Then a featureless grey frame with the simulator's sensor noise (2 DN): noise is no corner.
  cv::Mat grey(left_[0].size(), CV_8UC1);
  cv::RNG rng(5);
  rng.fill(grey, cv::RNG::NORMAL, 128, 2);
  EXPECT_TRUE(tracker.track(dataset_->frames[6].t_ns, grey, grey).features.empty());

  tracker.reset();
  const TrackedFrame back = tracker.track(dataset_->frames[7].t_ns, left_[7], right_[7]);
  EXPECT_GE(back.features.size(), 150u);
  for (const Feature& f : back.features) {
    EXPECT_GT(f.id, max_id);  // ids keep increasing over a reset
    EXPECT_EQ(f.track_length, 1);
  }
  const TrackedFrame next = tracker.track(dataset_->frames[8].t_ns, left_[8], right_[8]);
  EXPECT_GE(next.stats.tracked, 120);
}

TEST_F(FeatureTrackerTest, MonoTracksWithoutRightImage) {
  TrackerConfig config;
  config.stereo = false;
  FeatureTracker tracker(config);
  TrackedFrame f;
  for (std::size_t k = 0; k < 4; ++k) f = tracker.track(dataset_->frames[k].t_ns, left_[k]);
  EXPECT_GE(f.stats.tracked, 120);
  EXPECT_EQ(f.stats.stereo_matches, 0);
  for (const Feature& feat : f.features) EXPECT_FALSE(feat.has_right);
}

TEST_F(FeatureTrackerTest, SameFramesSameOutput) {
  FeatureTracker a{TrackerConfig{}}, b{TrackerConfig{}};
  for (std::size_t k = 0; k < 12; ++k) {
    const TrackedFrame fa = a.track(dataset_->frames[k].t_ns, left_[k], right_[k]);
    const TrackedFrame fb = b.track(dataset_->frames[k].t_ns, left_[k], right_[k]);
    ASSERT_EQ(fa.features.size(), fb.features.size()) << "frame " << k;
    for (std::size_t i = 0; i < fa.features.size(); ++i) {
      const Feature &x = fa.features[i], &y = fb.features[i];
      EXPECT_EQ(x.id, y.id);
      EXPECT_EQ(x.px_left, y.px_left);
      EXPECT_EQ(x.has_right, y.has_right);
      EXPECT_EQ(x.px_right, y.px_right);
      EXPECT_EQ(x.track_length, y.track_length);
    }
    EXPECT_EQ(fa.stats.rejected_fb, fb.stats.rejected_fb);
    EXPECT_EQ(fa.stats.rejected_ransac, fb.stats.rejected_ransac);
    EXPECT_EQ(fa.stats.rejected_stereo, fb.stats.rejected_stereo);
  }
}

std::string invalidInput(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InvalidInput";
  return {};
}

TEST(FeatureTrackerConfig, BadValuesNameTheField) {
  EXPECT_NO_THROW(TrackerConfig{}.validate());
  const std::vector<std::pair<std::string, std::function<void(TrackerConfig&)>>> cases = {
      {"max_features", [](TrackerConfig& c) { c.max_features = 0; }},
      {"quality_level", [](TrackerConfig& c) { c.quality_level = 0.0; }},
      {"quality_level", [](TrackerConfig& c) { c.quality_level = 1.5; }},
      {"min_distance_px", [](TrackerConfig& c) { c.min_distance_px = -1; }},
      {"grid_cols", [](TrackerConfig& c) { c.grid_cols = 0; }},
      {"grid_rows", [](TrackerConfig& c) { c.grid_rows = -2; }},
      {"klt_window_px", [](TrackerConfig& c) { c.klt_window_px = 20; }},
      {"klt_window_px", [](TrackerConfig& c) { c.klt_window_px = 1; }},
      {"klt_levels", [](TrackerConfig& c) { c.klt_levels = -1; }},
      {"klt_iterations", [](TrackerConfig& c) { c.klt_iterations = 0; }},
      {"klt_refine_window_px", [](TrackerConfig& c) { c.klt_refine_window_px = 8; }},
      {"klt_refine_window_px", [](TrackerConfig& c) { c.klt_refine_window_px = 1; }},
      {"klt_refine_window_px", [](TrackerConfig& c) { c.klt_refine_window_px = 23; }},
      {"fb_threshold_px", [](TrackerConfig& c) { c.fb_threshold_px = 0.0; }},
      {"ransac_threshold_px",
       [](TrackerConfig& c) { c.ransac_threshold_px = std::numeric_limits<double>::quiet_NaN(); }},
      {"stereo_max_vertical_px", [](TrackerConfig& c) { c.stereo_max_vertical_px = -1.0; }},
      {"klt_predict_min_px", [](TrackerConfig& c) { c.klt_predict_min_px = -1.0; }},
      {"klt_predict_min_px", [](TrackerConfig& c) { c.klt_predict_min_px = std::nan(""); }},
      {"detect_level", [](TrackerConfig& c) { c.detect_level = -1; }},
      {"detect_level", [](TrackerConfig& c) { c.detect_level = 4; }},
      {"stereo_min_zncc", [](TrackerConfig& c) { c.stereo_min_zncc = 1.5; }},
      {"min_eigen_ratio", [](TrackerConfig& c) { c.min_eigen_ratio = -0.1; }},
      {"min_eigen_ratio", [](TrackerConfig& c) { c.min_eigen_ratio = std::nan(""); }},
      {"stereo_min_zncc", [](TrackerConfig& c) { c.stereo_min_zncc = std::nan(""); }},
      {"gain_threshold", [](TrackerConfig& c) { c.gain_threshold = -0.01; }},
      {"gain_threshold", [](TrackerConfig& c) { c.gain_threshold = 1.0; }},
      {"gain_threshold", [](TrackerConfig& c) { c.gain_threshold = std::nan(""); }},
  };
  for (const auto& [field, spoil] : cases) {
    TrackerConfig c;
    spoil(c);
    EXPECT_THAT(invalidInput([&] { c.validate(); }), HasSubstr(field));
    EXPECT_THAT(invalidInput([&] { FeatureTracker{c}; }), HasSubstr(field));
  }
}

// The real EuRoC V1_01 clip, rectified as the pipeline does: the row check at 0.5 px around the
// median offset keeps most of what a 2 px tolerance keeps on a real rig (2026-11-29: 87 %; 94 %
// since the exposure correction matches this rig's darker right camera).
TEST(FeatureTrackerEuroc, TheRowCheckKeepsARealRigsMatches) {
  const std::vector<StereoPair> pairs = eurocClipRectified();
  if (pairs.empty()) GTEST_SKIP() << "shared data absent: euroc_v101_micro";
  TrackerConfig wide;
  wide.stereo_max_vertical_px = 2.0;
  FeatureTracker tight_tracker{TrackerConfig{}}, wide_tracker{wide};
  int tight = 0, loose = 0;
  double max_offset = 0.0;
  for (const StereoPair& p : pairs) {
    const TrackedFrame a = tight_tracker.track(p.t_ns, p.left, p.right);
    const TrackedFrame b = wide_tracker.track(p.t_ns, p.left, p.right);
    tight += a.stats.stereo_matches;
    loose += b.stats.stereo_matches;
    max_offset = std::max(max_offset, std::abs(a.stats.stereo_row_offset_px));
  }
  std::cout << "[ tracker ] EuRoC: " << tight << " stereo matches at 0.5 px around the median, "
            << loose << " at 2 px; largest median offset " << max_offset << " px\n";
  ASSERT_GT(loose, 0);
  EXPECT_GE(static_cast<double>(tight) / loose, 0.8);
  EXPECT_LT(max_offset, 0.5);
}

// Fraction of the features in view kept by the tracker at each frame of a pan (8 frames, the
// image moving left by 12 px more each frame, to 96 px), and, with `predict_tracks`, that each
// kept one lands on its true position (within 0.1 px).
std::vector<double> keptInAPan(bool predict_tracks) {
  constexpr int kW = 640, kH = 360, kSteps = 8, kAccelPx = 12;
  cv::Mat canvas(kH, kW + kAccelPx * kSteps * (kSteps + 1) / 2 + 8, CV_32F);
  cv::RNG rng(5);
  rng.fill(canvas, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(canvas, canvas, cv::Size(0, 0), 2.0);
  cv::normalize(canvas, canvas, 0, 255, cv::NORM_MINMAX);
  canvas.convertTo(canvas, CV_8U);
  TrackerConfig mono;
  mono.stereo = false;
  mono.klt_predict_min_px = predict_tracks ? TrackerConfig{}.klt_predict_min_px : 1e9;
  FeatureTracker tracker{mono};
  TrackedFrame previous = tracker.track(0, canvas(cv::Rect(0, 0, kW, kH)).clone());
  std::vector<double> kept_fraction;
  int x0 = 0;
  for (int k = 1; k <= kSteps; ++k) {
    const int step = kAccelPx * k;
    x0 += step;
    const TrackedFrame f =
        tracker.track(k * 100'000'000LL, canvas(cv::Rect(x0, 0, kW, kH)).clone());
    int in_view = 0, kept = 0;
    const auto now = byId(f);
    for (const Feature& p : previous.features) {
      if (p.px_left.x() - step < 4.0) continue;  // left the view (or its KLT window did)
      ++in_view;
      const auto it = now.find(p.id);
      if (it == now.end()) continue;
      ++kept;
      if (!predict_tracks) continue;
      EXPECT_NEAR(it->second.px_left.x(), p.px_left.x() - step, 0.1) << k;
      EXPECT_NEAR(it->second.px_left.y(), p.px_left.y(), 0.1) << k;
    }
    kept_fraction.push_back(static_cast<double>(kept) / std::max(in_view, 1));
    previous = f;
  }
  return kept_fraction;
}

// A pan that speeds up to 96 px a frame (a car turning into a corner: 3.8 deg a frame is 48 px on
// KITTI's camera): KLT starts every track shifted by the frame's common image motion (the tracks'
// median velocity, once it exceeds 10 px a frame), so the features that stay in view are kept.
// Started at the old position, the pyramid (3 levels, 21 px window) on this fine texture (blurred
// noise) loses a third of them at 24 px and 95 % from 48 px on (measured 2026-11-29; the few it
// keeps there are mostly at wrong positions: a lost KLT that stays near its start passes the
// forward-backward check, whose reverse pass starts at the old position).
TEST(FeatureTrackerPan, TracksStartShiftedByTheCommonImageMotion) {
  const std::vector<double> predicted = keptInAPan(true), unpredicted = keptInAPan(false);
  for (std::size_t k = 0; k < predicted.size(); ++k) {
    std::cout << fmt::format(
        "[ tracker ] pan of {} px: {:.2f} of the features in view kept, {:.2f} "
        "started at the old position\n",
        12 * (k + 1), predicted[k], unpredicted[k]);
    EXPECT_GE(predicted[k], 0.95) << k;
  }
  EXPECT_LT(unpredicted.back(), 0.5);  // the pan is beyond the pyramid's reach unpredicted
}

TEST(FeatureTrackerImages, MismatchedImagesThrow) {
  FeatureTracker tracker{TrackerConfig{}};
  const cv::Mat a(120, 160, CV_8UC1, cv::Scalar(0)), b(100, 160, CV_8UC1, cv::Scalar(0));
  const cv::Mat colour(120, 160, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_THAT(invalidInput([&] { tracker.track(0, a, b); }), HasSubstr("differ in size"));
  EXPECT_THAT(invalidInput([&] { tracker.track(0, a); }), HasSubstr("right image"));
  EXPECT_THAT(invalidInput([&] { tracker.track(0, colour, colour); }), HasSubstr("left image"));
  EXPECT_THAT(invalidInput([&] { tracker.track(0, a, colour(cv::Rect(0, 0, 160, 120))); }),
              HasSubstr("right image"));
  EXPECT_NO_THROW(tracker.track(0, a, a));
  EXPECT_THAT(invalidInput([&] { tracker.track(1, b, b); }), HasSubstr("size changed"));
  tracker.reset();
  EXPECT_NO_THROW(tracker.track(2, b, b));
}

// The demo dataset's 64 x 24 images are smaller than the pyramid asks for: no crash, sane output.
TEST(FeatureTrackerImages, TinyImagesWork) {
  cv::Mat img(24, 64, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
  FeatureTracker tracker{TrackerConfig{}};
  const TrackedFrame first = tracker.track(0, img, img);
  const TrackedFrame second = tracker.track(1, img, img);
  EXPECT_GT(first.features.size(), 0u);
  EXPECT_EQ(second.stats.tracked, static_cast<int>(first.features.size()));
  for (const Feature& f : second.features) {
    if (f.has_right) {
      EXPECT_NEAR((f.px_right - f.px_left).norm(), 0.0, 0.1);
    }
  }
}

// Corners found on the half-resolution level are placed on the full-resolution image's corners:
// light squares on grey, slightly blurred, whose 4 x 30 corners are known. The Shi-Tomasi
// response (3 x 3 blocks of 3 x 3 Sobel derivatives) peaks 1.5 px inside a square's outline on
// both axes, where the full-resolution detection puts all 120 (measured). Without the pyramid to
// take the level from (klt_levels 0) the tracker halves the image itself. (Level 2 placed 88
// of 120 there, the others up to 14 px off: a square's corners are 5 px apart at 1/4 scale.)
TEST(FeatureTrackerDetection, CornersFromACoarserLevelLieOnTheImagesCorners) {
  cv::Mat img(360, 720, CV_8UC1, cv::Scalar(60));
  std::vector<cv::Point2f> truth;
  for (int row = 0; row < 5; ++row) {
    for (int col = 0; col < 6; ++col) {
      const int x0 = 40 + 110 * col + 7 * row, y0 = 30 + 65 * row + 3 * col;
      cv::rectangle(img, cv::Rect(x0, y0, 41, 29), cv::Scalar(200), cv::FILLED);
      for (const float dx : {1.0F, 39.0F}) {
        for (const float dy : {1.0F, 27.0F}) truth.emplace_back(x0 + dx, y0 + dy);
      }
    }
  }
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.7);
  for (const int klt_levels : {3, 0}) {
    for (const int level : {0, 1}) {
      TrackerConfig c;
      c.stereo = false;
      c.max_features = 200;
      c.min_distance_px = 10;
      c.klt_levels = klt_levels;
      c.detect_level = level;
      FeatureTracker tracker{c};
      const TrackedFrame frame = tracker.track(0, img, cv::Mat());
      int on_corner = 0;
      for (const Feature& f : frame.features) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const cv::Point2f& t : truth) {
          nearest = std::min(nearest, std::hypot(f.px_left.x() - static_cast<double>(t.x),
                                                 f.px_left.y() - static_cast<double>(t.y)));
        }
        on_corner += nearest <= 1.0 ? 1 : 0;
      }
      SCOPED_TRACE(fmt::format("klt_levels {}, detect_level {}", klt_levels, level));
      EXPECT_GE(on_corner, 110);  // of 120
      EXPECT_EQ(on_corner, static_cast<int>(frame.features.size()));
    }
  }
}

}  // namespace
}  // namespace gvio::test
