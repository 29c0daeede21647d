// The paper's KF with its fixes screened as the smoother screens them (fusion/online_sigma_scale,
// fusion.kf.learn_noise): the scale is learned from the innovations per fix quality, never below
// the stated sigmas; on a drive whose receiver states sigmas three times too small the KF gates
// fewer good fixes and follows the truth more closely than trusting them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

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

}  // namespace
}  // namespace gvio::fusion
