// Place recognition pieces (mapping/loop_*.hpp) on synthetic data: loop features from an image,
// geometric verification recovering a known relative pose with a covariance that fits its error,
// failures named, and candidate search, plausibility and temporal consistency over a drive.
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <numbers>
#include <random>

#include <opencv2/imgproc.hpp>

#include "mapping/loop_closure.hpp"
#include "mapping/loop_features.hpp"
#include "mapping/loop_verification.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "support/kitti_camera.hpp"

namespace gvio::mapping {
namespace {

CameraModel kittiLikeCamera() {
  return test::kittiForwardCamera();
}

cv::Mat randomImage(std::uint64_t seed) {
  cv::Mat img(376, 1241, CV_8U);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.5);
  return img;
}

// A candidate keyframe with n points 5-25 m ahead, random 256-bit descriptors; the query sees the
// same points from T_q_c (candidate camera -> query camera) with 0.5 px noise, their descriptors
// with a few flipped bits, plus `outliers` keypoints with random descriptors.
struct SyntheticPair {
  LoopKeyframe candidate, query;
  Eigen::Isometry3d T_q_c = Eigen::Isometry3d::Identity();
};

SyntheticPair makePair(int n, int outliers, std::uint64_t seed) {
  const CameraModel cam = kittiLikeCamera();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  SyntheticPair s;
  s.T_q_c.linear() = odometry::expSo3(Eigen::Vector3d(0.01, -0.05, 0.02));
  s.T_q_c.translation() = Eigen::Vector3d(0.4, -0.05, -1.2);
  cv::Mat cand_desc(0, 32, CV_8U), query_desc(0, 32, CV_8U);
  while (static_cast<int>(s.candidate.points) < n) {
    const Eigen::Vector3d p{u01(rng) * 24.0 - 12.0, u01(rng) * 6.0 - 4.0, 5.0 + 20.0 * u01(rng)};
    const Eigen::Vector3d q = s.T_q_c * p;
    const Eigen::Vector2d px(cam.fx * q.x() / q.z() + cam.cx, cam.fy * q.y() / q.z() + cam.cy);
    if (q.z() < 1.0 || px.x() < 0 || px.y() < 0 || px.x() > 1240 || px.y() > 375) continue;
    cv::Mat d(1, 32, CV_8U);
    for (int b = 0; b < 32; ++b) d.at<std::uint8_t>(0, b) = static_cast<std::uint8_t>(rng() & 0xff);
    s.candidate.p_c.push_back(p.cast<float>());
    s.candidate.px.emplace_back(0.0F, 0.0F);  // unused for the candidate side
    cand_desc.push_back(d);
    ++s.candidate.points;
    cv::Mat dq = d.clone();
    for (int flip = 0; flip < 6; ++flip)
      dq.at<std::uint8_t>(0, static_cast<int>(rng() % 32)) ^= 1U << (rng() % 8);
    query_desc.push_back(dq);
    s.query.px.emplace_back(static_cast<float>(px.x() + 0.5 * n01(rng)),
                            static_cast<float>(px.y() + 0.5 * n01(rng)));
  }
  for (int k = 0; k < outliers; ++k) {
    cv::Mat d(1, 32, CV_8U);
    for (int b = 0; b < 32; ++b) d.at<std::uint8_t>(0, b) = static_cast<std::uint8_t>(rng() & 0xff);
    query_desc.push_back(d);
    s.query.px.emplace_back(static_cast<float>(u01(rng) * 1240),
                            static_cast<float>(u01(rng) * 375));
  }
  s.candidate.descriptors = cand_desc;
  s.query.descriptors = query_desc;
  return s;
}

TEST(LoopFeatures, KeypointsWithPointsFirstAndThumbnailsCorrelate) {
  const cv::Mat img = randomImage(1);
  std::vector<LoopPointInput> points;
  for (int k = 0; k < 50; ++k) {
    LoopPointInput p;
    p.px = Eigen::Vector2d(60.0 + 20.0 * k, 100.0 + 3.0 * k);
    p.has_point = k % 2 == 0;
    p.p_c = Eigen::Vector3d(0.1 * k, 0.0, k % 4 == 0 ? 10.0 : 50.0);  // half beyond 30 m
    points.push_back(p);
  }
  points.push_back({Eigen::Vector2d(3.0, 3.0), true, Eigen::Vector3d(0, 0, 10)});  // at the border
  LoopFeatureConfig config;
  const LoopKeyframe kf = makeLoopKeyframe(7, img, points, config);
  EXPECT_EQ(kf.points, 13U);     // k % 4 == 0 within the depth range
  EXPECT_EQ(kf.px.size(), 50U);  // the border keypoint has no descriptor
  EXPECT_EQ(kf.descriptors.rows, 50);
  for (std::size_t i = 0; i < kf.points; ++i) EXPECT_NEAR(kf.p_c[i].z(), 10.0F, 1e-6F);
  config.orb_features = 200;
  const LoopKeyframe more = makeLoopKeyframe(7, img, points, config);
  EXPECT_GT(more.px.size(), 150U);
  EXPECT_EQ(more.points, 13U);
  EXPECT_NEAR(thumbnailSimilarity(kf, more), 1.0F, 1e-5F);
  const LoopKeyframe other = makeLoopKeyframe(8, randomImage(2), points, LoopFeatureConfig{});
  EXPECT_LT(thumbnailSimilarity(kf, other), 0.5F);
  LoopFeatureConfig bad;
  bad.max_depth_m = 0.5;
  EXPECT_THROW(bad.validate(), InvalidInput);
}

TEST(LoopVerification, RecoversTheRelativePoseWithACovarianceThatFitsItsError) {
  const CameraModel cam = kittiLikeCamera();
  const LoopMatchConfig config;
  double nees_sum = 0.0;
  int trials = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const SyntheticPair s = makePair(120, 80, seed);
    const LoopMeasurement m = verifyLoop(s.query, s.candidate, cam, config);
    ASSERT_EQ(m.check, LoopCheck::kOk) << toString(m.check) << " seed " << seed;
    EXPECT_GE(m.inliers, 110);
    EXPECT_LT(m.reprojection_px, 1.0);
    const Eigen::Isometry3d truth = cam.T_b_c * s.T_q_c.inverse() * cam.T_b_c.inverse();
    Eigen::Matrix<double, 6, 1> e;
    e << odometry::logSo3(truth.rotation().transpose() * m.T_cand_query.rotation()),
        m.T_cand_query.translation() - truth.translation();
    EXPECT_LT(e.tail<3>().norm(), 0.05);
    nees_sum += e.dot(m.covariance.inverse() * e);
    ++trials;
  }
  // The normalised estimation error squared averages the 6 degrees of freedom when the
  // covariance is right; a factor of 3 either way still flags a wrong scale.
  const double nees = nees_sum / trials;
  std::printf("loop relative pose: NEES %.2f for 6 degrees of freedom\n", nees);
  EXPECT_GT(nees, 2.0);
  EXPECT_LT(nees, 18.0);
}

TEST(LoopVerification, NamesWhyACandidateFails) {
  const CameraModel cam = kittiLikeCamera();
  LoopMatchConfig config;
  SyntheticPair s = makePair(120, 0, 3);
  SyntheticPair unrelated = makePair(120, 0, 4);
  EXPECT_EQ(verifyLoop(unrelated.query, s.candidate, cam, config).check, LoopCheck::kFewMatches);
  LoopKeyframe empty;
  EXPECT_EQ(verifyLoop(s.query, empty, cam, config).check, LoopCheck::kNoPoints);
  // Matches whose geometry is noise: every query pixel scrambled.
  std::mt19937_64 rng(9);
  for (auto& px : s.query.px) {
    px = Eigen::Vector2f(static_cast<float>(rng() % 1240), static_cast<float>(rng() % 375));
  }
  const LoopMeasurement m = verifyLoop(s.query, s.candidate, cam, config);
  EXPECT_TRUE(m.check == LoopCheck::kFewInliers || m.check == LoopCheck::kPnpFailed)
      << toString(m.check);
  config.min_inliers = 3;
  EXPECT_THROW(config.validate(), InvalidInput);
}

}  // namespace
}  // namespace gvio::mapping
