// The paper's KF with its fixes screened as the smoother screens them (fusion/online_sigma_scale,
// fusion.kf.learn_noise): the scale is learned from the innovations per fix quality, never below
// the stated sigmas; on a drive whose receiver states sigmas three times too small the KF gates
// fewer good fixes and follows the truth more closely than trusting them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_fusion.hpp"
#include "fusion/online_sigma_scale.hpp"
#include "support/gnss_drive.hpp"

namespace gvio::fusion {
namespace {

TEST(OnlineSigmaScale, LearnsTheRatioOfTheSpreadToTheStatedSigmas) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  OnlineSigmaScale s;
  EXPECT_EQ(s.scale(1), Eigen::Vector2d::Ones());  // nothing seen yet
  for (int i = 0; i < 300; ++i) {
    // Innovations 3x (horizontal) and 2x (vertical) what the stated sigmas say; RTK fixed ones as
    // stated.
    // Drawn one by one: a call's argument order is the compiler's choice.
    const auto z2 = [&](double k) { return std::pow(k * n01(rng), 2); };
    const double e1 = z2(3.0), n1 = z2(3.0), u1 = z2(2.0);
    s.add(1, {e1, n1}, u1);
    const double e4 = z2(1.0), n4 = z2(1.0), u4 = z2(1.0);
    s.add(4, {e4, n4}, u4);
  }
  // The median of the last 200 (horizontal) / 100 (vertical) values: about 8 % / 11 % (1 sigma).
  EXPECT_NEAR(s.scale(1).x(), 3.0, 0.6);
  EXPECT_NEAR(s.scale(1).y(), 2.0, 0.6);
  EXPECT_EQ(s.scale(4).x(), std::max(1.0, s.scale(4).x()));  // never below the stated sigmas
  EXPECT_LT(s.scale(4).x(), 1.3);
  EXPECT_EQ(s.scales().size(), 2U);
}

FusionStats fuseKf(const test::GnssDrive& d, bool learn, double* rmse_out) {
  FusionConfig config;
  config.mode = FusionMode::kKf;
  config.lever_arm_b = d.lever;
  config.kf.learn_noise = learn;
  GnssFusion fusion(config, d.enu);
  test::replay(fusion, d);
  *rmse_out = test::rmse(d.truth, fusion.fusedTrajectory());
  return fusion.stats();
}

TEST(GnssFusionKf, ScreensOptimisticSigmasAsTheSmootherDoes) {
  // Fixes with 1.5 m h / 3 m v white noise and a 1 m Gauss-Markov bias, stated as 0.5 / 1 m.
  test::GnssDrive d = test::makeGnssDrive(-1, -1, 1.0, 60.0);
  for (GnssFix& fix : d.fixes) {
    fix.sigma_h_m = 0.5;
    fix.sigma_v_m = 1.0;
  }
  double learned = 0.0, stated = 0.0;
  const FusionStats a = fuseKf(d, true, &learned);
  const FusionStats b = fuseKf(d, false, &stated);
  ASSERT_EQ(a.kf_sigma_scale.size(), 1U);
  const Eigen::Vector2d scale = a.kf_sigma_scale.at(1);
  std::printf(
      "kf learned: %.3f m (sigmas x %.2f h, %.2f v, %d rejected), as stated: %.3f m (%d "
      "rejected)\n",
      learned, scale.x(), scale.y(), a.fixes_rejected, stated, b.fixes_rejected);
  EXPECT_GT(scale.x(), 2.0);
  EXPECT_LT(scale.x(), 4.5);
  EXPECT_LT(a.fixes_rejected, b.fixes_rejected);
  EXPECT_LT(learned, stated);
  EXPECT_TRUE(b.kf_sigma_scale.empty());
}

// A receiver that states thin ellipses (3 m x 0.5 m, turning with the geometry) with sigmas half
// the true ones: the along-track samples whitened by the stated ellipses learn about 2 (each
// draw within 25 %), and with the right sigmas about 1. Normalised by the circle of the same
// horizontal sigma instead, both axes' samples would learn about 1.56 and 0.78 (the short axes pull
// the median down); whitened across the track too, the filter's heading error would enter
// (learned 1.75-3.45, and up to 1.72 where 1 is right, over six such drives).
TEST(GnssFusionKf, LearnsTheScaleThroughTheStatedEllipses) {
  for (const std::uint64_t seed : {31u, 32u, 33u, 34u}) {
    const test::GnssDrive optimistic = test::makeEllipseGnssDrive(seed, 3.0, 0.5, 0.5);
    const test::GnssDrive right = test::makeEllipseGnssDrive(seed, 3.0, 0.5, 1.0);
    double rmse_optimistic = 0.0, rmse_right = 0.0;
    const FusionStats a = fuseKf(optimistic, true, &rmse_optimistic);
    const FusionStats b = fuseKf(right, true, &rmse_right);
    ASSERT_EQ(a.kf_sigma_scale.size(), 1U);
    ASSERT_EQ(b.kf_sigma_scale.size(), 1U);
    const Eigen::Vector2d half = a.kf_sigma_scale.at(1);
    const Eigen::Vector2d stated = b.kf_sigma_scale.at(1);
    std::printf(
        "seed %u: learned x %.2f h, %.2f v (stated half); x %.2f h, %.2f v (stated right)\n",
        static_cast<unsigned>(seed), half.x(), half.y(), stated.x(), stated.y());
    EXPECT_GT(half.x(), 1.5);
    EXPECT_LT(half.x(), 2.5);
    EXPECT_LT(stated.x(), 1.2);
  }
}

// The samples of a moving filter are along the track: a heading error of the filter (the VIO's
// step rotated by it) leaves them as they were; at a standstill both axes are whitened by the
// ellipse.
TEST(OnlineSigmaScale, DifferencedSamplesIgnoreTheFiltersHeadingError) {
  const Eigen::Matrix2d cov_h = ellipseCovariance(3.0, 0.5, 30.0);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.topLeftCorner<2, 2>() = cov_h;
  cov(2, 2) = 4.0;
  const Eigen::Vector2d step(8.0, 6.0);             // the VIO's step, 10 m
  const Eigen::Vector3d error(1.1, -0.7, 1.0);      // the fixes' differenced error
  const double heading_error = 1.0 * M_PI / 180.0;  // rotates the VIO's step
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(heading_error).toRotationMatrix();
  Eigen::Vector3d with_heading = error;
  with_heading.head<2>() += step - R * step;  // d = fixes' step - R (VIO step)
  const DifferencedNoiseSample exact = differencedNoiseSample(error, step, cov);
  const DifferencedNoiseSample rotated = differencedNoiseSample(with_heading, R * step, cov);
  const Eigen::Vector2d along = step.normalized();
  EXPECT_NEAR(exact.z2_horizontal.x(),
              std::pow(along.dot(error.head<2>()), 2) / along.dot(cov_h * along), 1e-12);
  EXPECT_TRUE(std::isnan(exact.z2_horizontal.y()));
  // Rotated, the sample is the fixes' error along the rotated track, whitened for that direction
  // (as good a sample of the receiver); the heading error itself enters to second order only.
  const Eigen::Vector2d along_r = R * along;
  const double expected_r =
      std::pow(along_r.dot(error.head<2>()), 2) / along_r.dot(cov_h * along_r);
  EXPECT_NEAR(rotated.z2_horizontal.x(), expected_r, 0.02 * expected_r);
  EXPECT_DOUBLE_EQ(exact.z2_vertical, 0.25);
  // Standing still: both axes, whitened (their sum is the Mahalanobis distance).
  const DifferencedNoiseSample still = differencedNoiseSample(error, Eigen::Vector2d::Zero(), cov);
  EXPECT_NEAR(still.z2_horizontal.sum(), error.head<2>().dot(cov_h.inverse() * error.head<2>()),
              1e-12);
  // A circle: per axis over its variance.
  const DifferencedNoiseSample circle =
      differencedNoiseSample(error, Eigen::Vector2d::Zero(), 4.0 * Eigen::Matrix3d::Identity());
  EXPECT_DOUBLE_EQ(circle.z2_horizontal.x(), 1.21 / 4.0);
  EXPECT_DOUBLE_EQ(circle.z2_horizontal.y(), 0.49 / 4.0);
}

}  // namespace
}  // namespace gvio::fusion
