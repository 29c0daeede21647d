// GNSS fix screening, VIO-world -> ENU registration and trajectory interpolation (fusion/).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "fusion/gnss_screening.hpp"
#include "fusion/vio_enu_alignment.hpp"

namespace gvio::fusion {
namespace {

GnssFix goodFix(std::int64_t t_ns) {
  GnssFix f;
  f.t_ns = t_ns;
  f.lat_deg = 48.98;
  f.lon_deg = 8.39;
  f.h_ellipsoid_m = 116.0;
  f.sigma_h_m = 1.5;
  f.sigma_v_m = 3.0;
  return f;
}

TEST(GnssScreening, SkipsAndCountsEveryKindOfBadFix) {
  std::vector<GnssFix> fixes;
  for (int k = 0; k < 10; ++k) fixes.push_back(goodFix(k * 1'000'000'000LL));
  fixes[1].lat_deg = std::numeric_limits<double>::quiet_NaN();
  fixes[2].sigma_h_m = 0.0;
  fixes[3].sigma_v_m = -1.0;
  fixes[4].lon_deg = 181.0;
  fixes[5].t_ns = fixes[4].t_ns - 1;  // earlier than a skipped fix, later than the kept ones: kept
  fixes.push_back(goodFix(60'000'000'000LL));  // far after the drive
  fixes.push_back(goodFix(5'500'000'000LL));   // back in time after a later fix
  const ScreeningResult r = screenFixes(fixes, 0, 9'000'000'000LL);
  EXPECT_EQ(r.counts.non_finite, 1);
  EXPECT_EQ(r.counts.bad_sigma, 2);
  EXPECT_EQ(r.counts.out_of_range, 1);
  EXPECT_EQ(r.counts.outside_drive, 1);
  EXPECT_EQ(r.counts.out_of_order, 1);
  EXPECT_EQ(r.counts.kept, 6);
  EXPECT_EQ(r.fixes.size(), 6U);
  for (std::size_t k = 1; k < r.fixes.size(); ++k) EXPECT_GT(r.fixes[k].t_ns, r.fixes[k - 1].t_ns);
  EXPECT_NE(r.counts.summary().find("6 skipped"), std::string::npos) << r.counts.summary();
  EXPECT_EQ(screenFixes({goodFix(0)}, 0, 1).counts.summary(), "");
}

std::vector<Eigen::Vector3d> randomPath(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-200.0, 200.0);
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < n; ++k) p.push_back(Eigen::Vector3d{u(rng), u(rng), 0.05 * u(rng)});
  return p;
}

TEST(VioEnuAlignment, RecoversYawAndTranslation) {
  std::mt19937 rng(1);
  const auto p_w = randomPath(rng, 50);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(100.0, -40.0, 3.0);
  std::vector<Eigen::Vector3d> p_enu;
  for (const auto& p : p_w) p_enu.push_back(T * p);
  const auto est = alignVioToEnu(p_w, p_enu, AlignmentDof::kYawTranslation);
  ASSERT_TRUE(est.has_value());
  EXPECT_LT((est->matrix() - T.matrix()).norm(), 1e-9);
}

TEST(VioEnuAlignment, FullRotationWithoutAnImu) {
  std::mt19937 rng(2);
  const auto p_w = randomPath(rng, 50);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(-1.0, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(5.0, 6.0, 7.0);
  std::vector<Eigen::Vector3d> p_enu;
  for (const auto& p : p_w) p_enu.push_back(T * p);
  const auto est = alignVioToEnu(p_w, p_enu, AlignmentDof::kRotationTranslation);
  ASSERT_TRUE(est.has_value());
  EXPECT_LT((est->matrix() - T.matrix()).norm(), 1e-9);
  // The yaw-only model cannot represent the tilt: its fit is worse, not silently equal.
  const auto yaw_only = alignVioToEnu(p_w, p_enu, AlignmentDof::kYawTranslation);
  ASSERT_TRUE(yaw_only.has_value());
  EXPECT_GT((yaw_only->matrix() - T.matrix()).norm(), 0.1);
}

// A straight path with noisy fixes: the roll about the path is unobservable, and an unconstrained
// full rotation tilts the world; below the cross-track spread the yaw solution stands in.
TEST(VioEnuAlignment, StraightPathFallsBackToYawWithoutAnImu) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.5);
  std::vector<Eigen::Vector3d> p_w, p_enu;
  for (int k = 0; k < 6; ++k) {
    p_w.emplace_back(8.0 * k, 0.0, 0.0);
    p_enu.push_back(Eigen::Vector3d(0.0, 8.0 * k, 0.0) +
                    Eigen::Vector3d{noise(rng), noise(rng), 2.0 * noise(rng)});
  }
  EXPECT_LT(crossExtent(p_w), 1e-9);
  const auto unconstrained = alignVioToEnu(p_w, p_enu, AlignmentDof::kRotationTranslation);
  const auto guarded = alignVioToEnu(p_w, p_enu, AlignmentDof::kRotationTranslation, 10.0, 10.0);
  ASSERT_TRUE(unconstrained && guarded);
  const auto tilt = [](const Eigen::Isometry3d& T) {
    return std::acos(std::clamp(T.linear()(2, 2), -1.0, 1.0));
  };
  EXPECT_GT(tilt(*unconstrained), 0.05);  // a straight line leaves the roll to the noise
  EXPECT_LT(tilt(*guarded), 1e-12);       // yaw only: the world's z stays up
  // With a real spread across the path, the guard lets the full rotation through.
  const auto wide = randomPath(rng, 20);
  EXPECT_GT(crossExtent(wide), 10.0);
  const auto full = alignVioToEnu(wide, wide, AlignmentDof::kRotationTranslation, 10.0, 10.0);
  ASSERT_TRUE(full);
  EXPECT_LT((full->matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-9);
}

TEST(VioEnuAlignment, RefusesTooFewOrTooClosePoints) {
  const std::vector<Eigen::Vector3d> two = {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()};
  EXPECT_FALSE(alignVioToEnu(two, two, AlignmentDof::kYawTranslation).has_value());
  const std::vector<Eigen::Vector3d> standing(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(alignVioToEnu(standing, standing, AlignmentDof::kYawTranslation).has_value());
}

TEST(InterpolatePose, LinearPositionSlerpRotationAndBounds) {
  Trajectory traj;
  traj.t_ns = {0, 400'000'000, 3'000'000'000};
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = a, c = a;
  b.translation() = Eigen::Vector3d(10, 0, 0);
  b.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.translation() = Eigen::Vector3d(20, 0, 0);
  traj.poses = {a, b, c};
  const auto mid = interpolatePose(traj, 100'000'000);
  ASSERT_TRUE(mid.has_value());
  EXPECT_LT((mid->translation() - Eigen::Vector3d(2.5, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(mid->rotation()).angle(), 0.1, 1e-12);
  EXPECT_TRUE(interpolatePose(traj, 400'000'000).has_value());
  EXPECT_FALSE(interpolatePose(traj, -1).has_value());
  EXPECT_FALSE(interpolatePose(traj, 3'000'000'001).has_value());
  EXPECT_FALSE(interpolatePose(traj, 2'000'000'000).has_value());  // inside a 2 s gap
  EXPECT_TRUE(interpolatePose(traj, 2'000'000'000, 3'000'000'000).has_value());
}

}  // namespace
}  // namespace gvio::fusion
