// mapping/image_consistency: the scores of a rendered map against a recorded image and stereo
// depth, and the robust flagging of the views that disagree (issue 19's per-keyframe check).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mapping/image_consistency.hpp"
#include "mapping/view_flags.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Blurred noise: texture at the scale of a few pixels, like a facade or asphalt.
cv::Mat texture(int width, int height, unsigned seed) {
  cv::Mat noise(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, noise, {0, 0}, 1.5);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  return noise;
}

struct Views {
  cv::Mat recorded, rendered, covered, rendered_depth, stereo_depth;
};

Views sameView(int width = 320, int height = 160) {
  Views v;
  v.recorded = texture(width, height, 1);
  v.rendered = v.recorded.clone();
  v.covered = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  v.rendered_depth = cv::Mat(height, width, CV_32FC1, cv::Scalar(10.0F));
  v.stereo_depth = v.rendered_depth.clone();
  return v;
}

constexpr double kFocalBaseline = 194.0;  // KITTI at half size, px m

ViewScore score(const Views& v, const ImageConsistencyConfig& c = {}) {
  return scoreView(v.recorded, v.rendered, v.covered, v.rendered_depth, v.stereo_depth,
                   kFocalBaseline, c);
}

TEST(ImageConsistency, ZnccIsOneForTheSameImageAndIgnoresGainAndOffset) {
  const cv::Mat a = texture(32, 32, 2);
  const cv::Mat mask(32, 32, CV_8UC1, cv::Scalar(255));
  EXPECT_NEAR(maskedZncc(a, a, mask, 1.0), 1.0, 1e-12);
  cv::Mat b;
  a.convertTo(b, CV_8UC1, 0.5, 40.0);
  EXPECT_NEAR(maskedZncc(a, b, mask, 1.0), 1.0, 0.01);
  cv::Mat inverted = 255 - a;
  EXPECT_NEAR(maskedZncc(a, inverted, mask, 1.0), -1.0, 1e-9);
  const cv::Mat flat(32, 32, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(std::isnan(maskedZncc(a, flat, mask, 1.0)));  // no texture: no verdict
  EXPECT_TRUE(std::isnan(maskedZncc(a, a, cv::Mat::zeros(32, 32, CV_8UC1), 1.0)));
}

TEST(ImageConsistency, ZnccCountsOnlyTheMaskedPixels) {
  const cv::Mat a = texture(32, 32, 3);
  cv::Mat b = a.clone();
  cv::Mat mask(32, 32, CV_8UC1, cv::Scalar(255));
  b(cv::Rect(0, 0, 32, 8)).setTo(0);  // garbage where the render drew nothing
  mask(cv::Rect(0, 0, 32, 8)).setTo(0);
  EXPECT_NEAR(maskedZncc(a, b, mask, 1.0), 1.0, 1e-12);
}

TEST(ImageConsistency, ARenderInPlaceScoresHighAndAShiftedOneLow) {
  const Views same = sameView();
  const ViewScore good = score(same);
  EXPECT_NEAR(good.ncc, 1.0, 1e-9);
  EXPECT_NEAR(good.ncc_se, 0.0, 1e-9);  // every patch agrees alike
  EXPECT_EQ(good.patches, (320 / 16) * (160 / 16));
  EXPECT_DOUBLE_EQ(good.coverage, 1.0);
  EXPECT_DOUBLE_EQ(good.depth_agreement, 1.0);
  Views shifted = same;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, 6, 0, 1, 0);  // 6 px to the right
  cv::warpAffine(same.recorded, shifted.rendered, M, same.recorded.size(), cv::INTER_LINEAR,
                 cv::BORDER_REFLECT);
  EXPECT_LT(score(shifted).ncc, 0.3);
}

TEST(ImageConsistency, DepthAgreesWithinOneDisparityPixel) {
  const ImageConsistencyConfig c;
  // 1 px of disparity at 10 m with f b = 194 px m: 100 / 194 = 0.515 m.
  EXPECT_NEAR(depthTolerance(10.0, kFocalBaseline, c), 100.0 / 194.0, 1e-12);
  EXPECT_DOUBLE_EQ(depthTolerance(1.0, kFocalBaseline, c), c.depth_tolerance_m);  // the floor
  Views v = sameView();
  v.rendered_depth.setTo(10.4F);  // within 0.515 m
  EXPECT_DOUBLE_EQ(score(v).depth_agreement, 1.0);
  v.rendered_depth(cv::Rect(0, 0, 160, 160)).setTo(11.0F);  // half the image 1 m too deep
  EXPECT_NEAR(score(v).depth_agreement, 0.5, 1e-12);
  EXPECT_EQ(score(v).depth_cells, (320 / 16) * (160 / 16));
  EXPECT_GT(score(v).depth_se, 0.0);  // agreeing and disagreeing patches
  // Every patch disagreeing alike: the spread is 0, the binomial floor over 200 patches is not.
  v.rendered_depth.setTo(11.0F);
  EXPECT_DOUBLE_EQ(score(v).depth_agreement, 0.0);
  EXPECT_NEAR(score(v).depth_se, std::sqrt(2.0 / 204.0 * (1.0 - 2.0 / 204.0) / 200.0), 1e-12);
  v.stereo_depth.setTo(0.0F);  // no stereo depth: not scored
  EXPECT_TRUE(std::isnan(score(v).depth_agreement));
  EXPECT_EQ(score(v).depth_pixels, 0U);
}

TEST(ImageConsistency, AnUncoveredViewIsNotScored) {
  Views v = sameView();
  v.covered.setTo(0);
  const ViewScore s = score(v);
  EXPECT_FALSE(s.hasNcc());
  EXPECT_EQ(s.patches, 0);
  EXPECT_DOUBLE_EQ(s.coverage, 0.0);
}

TEST(ImageConsistency, MismatchedImagesAndBadConfigAreRefused) {
  Views v = sameView();
  v.rendered_depth = cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.0F));
  EXPECT_THROW((void)score(v), InvalidInput);
  v = sameView();
  v.covered.convertTo(v.covered, CV_32F);
  EXPECT_THROW((void)score(v), InvalidInput);
  ImageConsistencyConfig c;
  c.patch_px = 2;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = {};
  c.min_patch_coverage = 0.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = {};
  c.flag_sigmas = -1.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = {};
  c.local_window_s = std::numeric_limits<double>::infinity();
  EXPECT_THROW(c.validate(), InvalidInput);
}

// Scores along a drive: a slow trend (scenery) with noise, and `dip` subtracted on [from, to).
std::vector<ViewScore> drive(std::size_t n, double dip, std::size_t from, std::size_t to) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<ViewScore> views(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double trend = 0.45 + 0.3 * static_cast<double>(i) / static_cast<double>(n);
    views[i].ncc = trend + noise(rng) - (i >= from && i < to ? dip : 0.0);
    views[i].depth_agreement = 0.9 + 0.5 * noise(rng);
    views[i].coverage = 0.4;
  }
  return views;
}

std::vector<double> times(std::size_t n) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = 0.2 * static_cast<double>(i);
  return t;
}

TEST(ImageConsistency, AShortDipIsFlaggedAndTheSceneryTrendIsNot) {
  const std::size_t n = 300;
  const FlaggedViews clean = flagOutliers(drive(n, 0.0, 0, 0), times(n), {});
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_FALSE(clean.flagged[i]) << i;
    EXPECT_EQ(clean.status[i], ViewStatus::kOk) << i;
  }
  const FlaggedViews faulty = flagOutliers(drive(n, 0.25, 200, 210), times(n), {});
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(faulty.flagged[i], i >= 200 && i < 210) << i;
  }
  // The flag says which score, against which threshold, on how much support.
  EXPECT_THAT(faulty.reason[205], testing::HasSubstr("ncc "));
  EXPECT_THAT(faulty.reason[205], testing::HasSubstr("local median"));
  EXPECT_THAT(faulty.reason[205], testing::HasSubstr("over 0 patches"));
  EXPECT_LT(faulty.ncc.z[205], -4.0);
  EXPECT_TRUE(faulty.reason[100].empty());
  const auto stretches = flaggedStretches(faulty.flagged);
  ASSERT_EQ(stretches.size(), 1U);
  EXPECT_EQ(stretches[0].first, 200U);
  EXPECT_EQ(stretches[0].last, 209U);
  // A long bad stretch moves the local medians with it; the floor (ZNCC 0.15) still flags a map
  // that does not correlate with its images.
  const FlaggedViews long_fault = flagOutliers(drive(n, 0.6, 100, 170), times(n), {});
  for (std::size_t i = 110; i < 160; ++i) EXPECT_TRUE(long_fault.flagged[i]) << i;
  for (std::size_t i = 180; i < n; ++i) EXPECT_FALSE(long_fault.flagged[i]) << i;
}

TEST(ImageConsistency, UnscoredViewsAndShortDrivesNeverFlag) {
  std::vector<ViewScore> views = drive(5, 0.5, 2, 3);
  views[2].ncc = 0.3;  // far below the others, but above the floor
  const FlaggedViews few = flagOutliers(views, times(5), {});
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_FALSE(few.flagged[i]);  // below min_views_to_flag: nothing is typical yet
    EXPECT_EQ(few.status[i], ViewStatus::kNotEnoughEvidence);
  }
  views[2].ncc = 0.1;
  EXPECT_TRUE(flagOutliers(views, times(5), {}).flagged[2]);  // the floor holds on any drive
  views[2].ncc_se = 0.02;  // ... when the view's own error cannot lift it above the floor
  EXPECT_FALSE(flagOutliers(views, times(5), {}).flagged[2]);
  views = drive(100, 0.0, 0, 0);
  views[50].ncc = kNan;
  views[50].depth_agreement = kNan;
  const FlaggedViews unscored = flagOutliers(views, times(100), {});
  EXPECT_FALSE(unscored.flagged[50]);
  EXPECT_EQ(unscored.status[50], ViewStatus::kNotEnoughEvidence);
  EXPECT_STREQ(toString(unscored.status[50]), "not_enough_evidence");
  EXPECT_THROW((void)flagOutliers(views, times(99), {}), InvalidInput);
  std::vector<double> unsorted = times(100);
  std::swap(unsorted[3], unsorted[4]);
  EXPECT_THROW((void)flagOutliers(views, unsorted, {}), InvalidInput);
}

// A view with few patches (the first and last keyframes see the map from one side) has a large
// standard error: the same dip flags it only when its error is small.
TEST(ImageConsistency, AViewWithLittleSupportNeedsALargerDip) {
  std::vector<ViewScore> views = drive(100, 0.0, 0, 0);
  views[99].ncc -= 0.25;
  views[99].ncc_se = 0.1;
  views[99].patches = 12;
  EXPECT_FALSE(flagOutliers(views, times(100), {}).flagged[99]);
  views[99].ncc_se = 0.01;
  views[99].patches = 400;
  const FlaggedViews f = flagOutliers(views, times(100), {});
  EXPECT_TRUE(f.flagged[99]);
  EXPECT_THAT(f.reason[99], testing::HasSubstr("over 400 patches"));
}

// A misregistered map makes the view's patches disagree among themselves (some still match, some
// no longer do), so its own standard error grows with the fault; the rule judges it by the error
// a correct view of its support would have.
TEST(ImageConsistency, AFaultsOwnSpreadDoesNotHideIt) {
  std::vector<ViewScore> views = drive(100, 0.0, 0, 0);
  for (ViewScore& v : views) {
    v.ncc_se = 0.01;
    v.patches = 300;
  }
  views[50].ncc -= 0.15;
  views[50].ncc_se = 0.05;
  EXPECT_TRUE(flagOutliers(views, times(100), {}).flagged[50]);
  views[50].patches = 12;  // ... but few patches are a larger error whatever their spread
  EXPECT_FALSE(flagOutliers(views, times(100), {}).flagged[50]);
}

// A drive's last keyframes see a map measured from behind only: they score low with a correct
// map, and are judged by the floor alone (not enough evidence otherwise).
TEST(ImageConsistency, AViewOfAMapMeasuredFromBehindOnlyIsJudgedByTheFloorAlone) {
  std::vector<ViewScore> views = drive(100, 0.0, 0, 0);
  views[99].ncc -= 0.3;
  views[99].ncc_se = 0.01;
  views[99].patches = 300;
  EXPECT_TRUE(flagOutliers(views, times(100), {}).flagged[99]);
  views[99].one_sided = true;
  const FlaggedViews f = flagOutliers(views, times(100), {});
  EXPECT_FALSE(f.flagged[99]);
  EXPECT_EQ(f.status[99], ViewStatus::kNotEnoughEvidence);
  views[99].ncc = 0.05;  // a map that does not correlate with its image, from any side
  EXPECT_TRUE(flagOutliers(views, times(100), {}).flagged[99]);
}

// How well stereo depths agree depends on the world's surfaces: a drive that agrees little
// everywhere (a low-texture road) flags nothing for it; a dip against the drive's own level does.
TEST(ImageConsistency, DepthAgreementIsJudgedAgainstTheDrivesOwnLevel) {
  std::vector<ViewScore> views = drive(100, 0.0, 0, 0);
  for (ViewScore& v : views) v.depth_agreement = std::max(0.0, v.depth_agreement - 0.85);
  const FlaggedViews low = flagOutliers(views, times(100), {});
  for (std::size_t i = 0; i < 100; ++i) EXPECT_FALSE(low.flagged[i]) << i;
  views = drive(100, 0.0, 0, 0);
  views[40].depth_agreement = 0.5;  // far below the drive's 0.9 +- 0.01
  views[40].depth_se = 0.02;
  views[40].depth_cells = 80;
  const FlaggedViews dip = flagOutliers(views, times(100), {});
  EXPECT_TRUE(dip.flagged[40]);
  EXPECT_THAT(dip.reason[40], testing::HasSubstr("depth agreement 0.500 <"));
  EXPECT_THAT(dip.reason[40], testing::HasSubstr("over 80 patches"));
  views[40].depth_se = 0.15;  // a few disagreeing patches: not evidence enough
  EXPECT_FALSE(flagOutliers(views, times(100), {}).flagged[40]);
}

// Views whose map is drawn near (slow sharp turns facing a wall, 12 s apart) score lower and
// spread wider with a correct map: judged among the views drawn as near elsewhere in the drive,
// they flag nothing, while a dip below their own level, or a dip of a view drawn far, still flags.
TEST(ImageConsistency, ViewsDrawnNearAreJudgedAmongTheViewsDrawnAsNear) {
  const std::size_t n = 400;
  std::vector<ViewScore> views = drive(n, 0.0, 0, 0);
  std::mt19937 rng(11);
  std::normal_distribution<double> wider(0.0, 0.04);
  std::vector<bool> near(n, false);
  for (std::size_t turn = 20; turn + 8 <= n; turn += 60) {
    for (std::size_t i = turn; i < turn + 8; ++i) near[i] = true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    views[i].drawn_depth_m = near[i] ? 8.0 : 20.0;
    if (near[i]) views[i].ncc -= 0.1 + wider(rng);
  }
  ImageConsistencyConfig whole_drive;
  whole_drive.similar_views = 0;
  const FlaggedViews alike = flagOutliers(views, times(n), whole_drive);
  EXPECT_GT(std::count(alike.flagged.begin(), alike.flagged.end(), true), 8);
  const FlaggedViews peers = flagOutliers(views, times(n), {});
  for (std::size_t i = 0; i < n; ++i) EXPECT_FALSE(peers.flagged[i]) << i;

  views[84].ncc -= 0.3;   // below the views drawn as near
  views[170].ncc -= 0.2;  // below the views drawn far
  const FlaggedViews faults = flagOutliers(views, times(n), {});
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(faults.flagged[i], i == 84 || i == 170) << i;
  EXPECT_THAT(faults.reason[84], testing::HasSubstr("as near"));
  EXPECT_LT(faults.ncc.reference[84], faults.ncc.reference[170] - 0.05);
}

// A faulty stretch's views are alike (here all drawn at 8 m, every other view at 20 m) but lie
// within local_window_s of each other: they are never each other's reference, so the stretch
// stands out against the views drawn as near elsewhere (none: the whole drive's level).
TEST(ImageConsistency, AFaultyStretchIsNotItsOwnReference) {
  const std::size_t n = 300;
  std::vector<ViewScore> views = drive(n, 0.25, 200, 220);
  for (std::size_t i = 0; i < n; ++i) views[i].drawn_depth_m = i >= 200 && i < 220 ? 8.0 : 20.0;
  const FlaggedViews f = flagOutliers(views, times(n), {});
  EXPECT_GE(std::count(f.flagged.begin() + 200, f.flagged.begin() + 220, true), 15);
  for (std::size_t i = 0; i < n; ++i) {
    if (i < 200 || i >= 220) {
      EXPECT_FALSE(f.flagged[i]) << i;
    }
  }
}

// Without drawn depths (or with every view drawn alike) the rule is the whole drive's.
TEST(ImageConsistency, WithoutDrawnDepthsEveryViewIsJudgedAgainstTheWholeDrive) {
  const std::vector<ViewScore> views = drive(300, 0.25, 200, 210);
  ImageConsistencyConfig whole_drive;
  whole_drive.similar_views = 0;
  const FlaggedViews a = flagOutliers(views, times(300), {});
  const FlaggedViews b = flagOutliers(views, times(300), whole_drive);
  EXPECT_EQ(a.flagged, b.flagged);
  EXPECT_EQ(a.ncc.below, b.ncc.below);
  whole_drive.similar_views = 3;  // fewer than min_views_to_flag: nothing typical to learn
  EXPECT_THROW(whole_drive.validate(), InvalidInput);
}

TEST(ImageConsistency, StretchesJoinAcrossOneUnflaggedView) {
  const std::vector<bool> f = {false, true, true, false, true, false, false, true};
  const auto s = flaggedStretches(f);
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(s[0].first, 1U);
  EXPECT_EQ(s[0].last, 4U);
  EXPECT_EQ(s[1].first, 7U);
  EXPECT_EQ(s[1].last, 7U);
  EXPECT_TRUE(flaggedStretches({false, false}).empty());
}

}  // namespace
}  // namespace gvio::mapping
