// The graph's offline smoothing pass (fusion/gnss_smoother.hpp): exact on exact data, and on a
// synthetic drive whose fixes carry a Gauss-Markov bias it beats the causal output and the same
// smoother without the bias state.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "fusion/gnss_fusion.hpp"
#include "fusion/gnss_smoother.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "support/gnss_drive.hpp"

namespace gvio::fusion {
namespace {

struct Fused {
  Trajectory online, smoothed;
  FusionStats stats;
  std::vector<PoseCovariance> covariance;
};

Fused fuse(const test::GnssDrive& d, const SmootherConfig& smoother) {
  FusionConfig config;
  config.lever_arm_b = d.lever;
  config.smoother = smoother;
  GnssFusion fusion(config, d.enu);
  test::replay(fusion, d);
  return {fusion.fusedTrajectory(), fusion.smoothedTrajectory(), fusion.stats(),
          fusion.smoothedCovariance()};
}

using test::rmse;

TEST(GnssSmoother, SpreadsExactNodesOverAnExactVioExactly) {
  // VIO = truth seen from a rotated, shifted world; nodes at every 7th pose hold the true pose.
  const test::GnssDrive d = test::makeGnssDrive();
  Eigen::Isometry3d T_w_enu = Eigen::Isometry3d::Identity();
  T_w_enu.linear() = odometry::expSo3(Eigen::Vector3d(0, 0, 0.7));
  T_w_enu.translation() = Eigen::Vector3d(5, -3, 1);
  Trajectory vio;
  std::vector<SmootherFix> nodes;
  SmoothedNodes smoothed;
  for (std::size_t k = 0; k < 400; ++k) {
    vio.t_ns.push_back(d.truth.t_ns[k]);
    vio.poses.push_back(T_w_enu * d.truth.poses[k]);
    if (k % 7 == 3) {
      nodes.push_back(
          {d.truth.t_ns[k], vio.poses.back(), d.truth.poses[k], Eigen::Vector3d::Zero(), 1.0, 1.0});
      smoothed.T_enu_b.push_back(d.truth.poses[k]);
    }
  }
  const Trajectory out = spreadOverVio(vio, nodes, smoothed);
  ASSERT_EQ(out.size(), vio.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_LT((out.poses[k].matrix() - d.truth.poses[k].matrix()).norm(), 1e-9) << k;
  }
}

TEST(GnssSmoother, BeatsTheCausalOutputOnBiasedFixes) {
  // 300 s, fixes with white noise 1.5 m h / 3 m v plus a 1 m Gauss-Markov bias (tau 60 s).
  const test::GnssDrive d = test::makeGnssDrive(-1, -1, 1.0, 60.0);
  SmootherConfig with_bias;
  with_bias.bias_ratio = 1.0 / 1.5;  // the drive's bias sigma over the fixes' reported sigma
  SmootherConfig without_bias;
  without_bias.bias_ratio = 0.0;
  const Fused a = fuse(d, with_bias);
  const Fused b = fuse(d, without_bias);
  ASSERT_EQ(a.smoothed.size(), d.vio.size());
  ASSERT_EQ(b.smoothed.size(), d.vio.size());
  const double online = rmse(d.truth, a.online);
  const double smoothed = rmse(d.truth, a.smoothed);
  const double smoothed_no_bias = rmse(d.truth, b.smoothed);
  std::printf("online %.3f m, smoothed %.3f m (no bias state: %.3f m), smoothing %.1f ms\n", online,
              smoothed, smoothed_no_bias, a.stats.ms_smoothing);
  // The floor for a drift-free VIO is about 0.97 m here (the bias is indistinguishable from the
  // trajectory's offset over its correlation time; this VIO also drifts 3 deg in yaw).
  EXPECT_LT(smoothed, 0.75 * online);
  EXPECT_LT(smoothed, smoothed_no_bias);
  EXPECT_LT(smoothed, 1.3);

  // The reported position covariance is consistent with the errors: the mean normalised squared
  // error (NEES, 3 dof) is near 3, neither overconfident (>> 3) nor uselessly loose (<< 3).
  ASSERT_EQ(a.covariance.size(), a.smoothed.size());
  double nees = 0.0;
  for (std::size_t k = 0; k < a.smoothed.size(); ++k) {
    const Eigen::Vector3d e = a.smoothed.poses[k].translation() - d.truth.poses[k].translation();
    nees += e.dot(a.covariance[k].bottomRightCorner<3, 3>().ldlt().solve(e));
  }
  nees /= static_cast<double>(a.smoothed.size());
  std::printf("position NEES %.2f (3 dof)\n", nees);
  EXPECT_GT(nees, 1.0);
  EXPECT_LT(nees, 9.0);
}

TEST(GnssSmoother, IsOffInKfModeAndWhenDisabled) {
  const test::GnssDrive d = test::makeGnssDrive();
  SmootherConfig off;
  off.enabled = false;
  EXPECT_TRUE(fuse(d, off).smoothed.empty());
  FusionConfig config;
  config.mode = FusionMode::kKf;
  config.lever_arm_b = d.lever;
  GnssFusion kf(config, d.enu);
  test::replay(kf, d);
  EXPECT_FALSE(kf.fusedTrajectory().empty());
  EXPECT_TRUE(kf.smoothedTrajectory().empty());
}

TEST(SmootherConfig, RejectsInvalidValues) {
  SmootherConfig c;
  c.bias_ratio = -1.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = SmootherConfig{};
  c.bias_tau_s = 0.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = SmootherConfig{};
  c.max_iterations = 0;
  EXPECT_THROW(c.validate(), InvalidInput);
}

}  // namespace
}  // namespace gvio::fusion
