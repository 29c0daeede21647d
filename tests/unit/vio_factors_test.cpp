// Jacobians of the estimator's residuals against central differences taken through the pose
// manifold's Plus, and the manifold's own invariants (Ceres' test utilities).
#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <random>

#include "odometry/imu_factor.hpp"
#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"
#include "odometry/prior_factor.hpp"
#include "odometry/reprojection_factor.hpp"
#include "odometry/time_offset_factor.hpp"
#include "support/ceres_jacobian.hpp"
#include "support/numeric_jacobian.hpp"

namespace gvio::odometry {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using test::analyticTangentJacobian;
using test::numericTangentJacobian;

std::array<double, 7> randomPose(std::mt19937& rng, double spread_m) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSo3(Eigen::Vector3d{n(rng), n(rng), n(rng)} * 0.5);
  T.translation() = Eigen::Vector3d{n(rng), n(rng), n(rng)} * spread_m;
  std::array<double, 7> x{};
  poseToBlock(T, x.data());
  return x;
}

TEST(PoseManifold, SatisfiesCeresManifoldInvariants) {
  using namespace ceres;  // NOLINT: the Ceres macro below names its helpers unqualified
  PoseManifold manifold;
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const std::array<double, 7> x = randomPose(rng, 10.0);
    const std::array<double, 7> y = randomPose(rng, 10.0);
    Eigen::Map<const Eigen::Matrix<double, 7, 1>> xv(x.data()), yv(y.data());
    Vector6d delta;
    for (int k = 0; k < 6; ++k) delta(k) = 0.3 * n(rng);
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, xv, delta, yv, 1e-9);
  }
}

TEST(PoseManifold, BlockRoundTripAndBodySidePerturbation) {
  std::mt19937 rng(3);
  const std::array<double, 7> x = randomPose(rng, 5.0);
  const Eigen::Isometry3d T = poseFromBlock(x.data());
  PoseManifold manifold;
  Vector6d delta;
  delta << 0.01, -0.02, 0.03, 0.5, -0.4, 0.2;
  std::array<double, 7> moved{};
  ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), moved.data()));
  const Eigen::Isometry3d T_moved = poseFromBlock(moved.data());
  EXPECT_LT((T_moved.linear() - T.linear() * expSo3(delta.head<3>())).norm(), 1e-12);
  EXPECT_LT((T_moved.translation() - (T.translation() + T.linear() * delta.tail<3>())).norm(),
            1e-12);
}

TEST(ImuFactor, JacobiansMatchNumericDerivatives) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  ImuNoise noise;
  ImuBias bias;
  bias.acc = Eigen::Vector3d(0.05, -0.03, 0.02);
  bias.gyr = Eigen::Vector3d(0.001, 0.002, -0.001);
  auto pre = std::make_shared<ImuPreintegration>(bias, noise);
  for (int k = 0; k < 50; ++k) {
    pre->integrate(0.01, Eigen::Vector3d(0.5 + 0.1 * n(rng), 0.2, 9.7),
                   Eigen::Vector3d(0.01, -0.05, 0.2 + 0.01 * n(rng)));
  }
  const ImuFactor factor(pre, Eigen::Vector3d(0, 0, -kGravity_mps2));
  std::vector<std::vector<double>> blocks(4);
  for (std::size_t b : {0UL, 2UL}) {
    const auto pose = randomPose(rng, 3.0);
    blocks[b].assign(pose.begin(), pose.end());
  }
  for (std::size_t b : {1UL, 3UL}) {
    blocks[b].resize(9);
    for (double& v : blocks[b]) v = 0.1 * n(rng);
  }
  for (std::size_t b = 0; b < 4; ++b) {
    const bool is_pose = b % 2 == 0;
    const auto num = numericTangentJacobian<15>(factor, blocks, b, is_pose);
    const auto ana = analyticTangentJacobian<15>(factor, blocks, b, is_pose);
    EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << b;
  }
}

TEST(ImuFactor, ResidualIsZeroOnTheIntegratedState) {
  ImuNoise noise;
  auto pre = std::make_shared<ImuPreintegration>(ImuBias{}, noise);
  for (int k = 0; k < 100; ++k)
    pre->integrate(0.01, Eigen::Vector3d(1, 0, 9.81), Eigen::Vector3d(0, 0, 0.1));
  const Eigen::Vector3d g(0, 0, -kGravity_mps2);
  const ImuFactor factor(pre, g);
  const double dt = pre->deltaT();
  Eigen::Isometry3d T_i = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_i(2, 0, 0);
  Eigen::Isometry3d T_j = Eigen::Isometry3d::Identity();
  T_j.linear() = pre->deltaR();
  T_j.translation() = v_i * dt + 0.5 * g * dt * dt + pre->deltaP();
  const Eigen::Vector3d v_j = v_i + g * dt + pre->deltaV();
  std::array<double, 7> pi{}, pj{};
  poseToBlock(T_i, pi.data());
  poseToBlock(T_j, pj.data());
  std::array<double, 9> si{}, sj{};
  Eigen::Map<Eigen::Vector3d>{si.data()} = v_i;
  Eigen::Map<Eigen::Vector3d>{sj.data()} = v_j;
  const double* params[] = {pi.data(), si.data(), pj.data(), sj.data()};
  std::array<double, 15> r{};
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  const Eigen::Map<const Eigen::Matrix<double, 15, 1>> residual(r.data());
  EXPECT_LT(residual.norm(), 1e-6);
}

struct ReprojectionSetup {
  PinholeView left, right;
  std::vector<std::vector<double>> blocks;
  Eigen::Vector3d bearing;
};

ReprojectionSetup makeReprojectionSetup() {
  ReprojectionSetup s;
  s.left.fx = s.left.fy = 718.856;
  s.left.cx = 607.19;
  s.left.cy = 185.2;
  // KITTI-like camera: z forward in a body whose x is forward.
  Eigen::Matrix3d R_b_c;
  R_b_c << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  s.left.T_b_c.linear() = R_b_c;
  s.left.T_b_c.translation() = Eigen::Vector3d(1.08, -0.32, 0.73);
  s.right = s.left;
  s.right.T_b_c.translation() += R_b_c * Eigen::Vector3d(0.537, 0, 0);
  Eigen::Isometry3d T_i = Eigen::Isometry3d::Identity();
  T_i.linear() = expSo3(Eigen::Vector3d(0.01, -0.02, 0.3));
  T_i.translation() = Eigen::Vector3d(5, 2, 0.1);
  Eigen::Isometry3d T_j = T_i;
  T_j.translation() += T_i.linear() * Eigen::Vector3d(1.5, 0.1, 0.02);
  T_j.linear() = T_j.linear() * expSo3(Eigen::Vector3d(0.005, 0.01, -0.05));
  s.blocks.assign(3, {});
  s.blocks[0].resize(7);
  s.blocks[1].resize(7);
  poseToBlock(T_i, s.blocks[0].data());
  poseToBlock(T_j, s.blocks[1].data());
  s.bearing = Eigen::Vector3d(0.1, -0.05, 1.0);
  s.blocks[2] = {1.0 / 12.0};
  return s;
}

TEST(ReprojectionFactor, JacobiansMatchNumericDerivatives) {
  const ReprojectionSetup s = makeReprojectionSetup();
  for (const PinholeView* observer : {&s.left, &s.right}) {
    const ReprojectionFactor factor(s.bearing, s.left.T_b_c, *observer,
                                    Eigen::Vector2d(650.0, 170.0), 1.5);
    for (std::size_t b = 0; b < 3; ++b) {
      const bool is_pose = b < 2;
      const auto num = numericTangentJacobian<2>(factor, s.blocks, b, is_pose);
      const auto ana = analyticTangentJacobian<2>(factor, s.blocks, b, is_pose);
      EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << b;
    }
  }
}

TEST(ReprojectionFactor, ZeroResidualAtTheTrueProjection) {
  const ReprojectionSetup s = makeReprojectionSetup();
  const Eigen::Isometry3d T_i = poseFromBlock(s.blocks[0].data());
  const Eigen::Isometry3d T_j = poseFromBlock(s.blocks[1].data());
  const Eigen::Vector3d P_w = T_i * s.left.T_b_c * (s.bearing / s.blocks[2][0]);
  const Eigen::Vector3d P_c = (T_j * s.right.T_b_c).inverse() * P_w;
  const Eigen::Vector2d px(s.right.fx * P_c.x() / P_c.z() + s.right.cx,
                           s.right.fy * P_c.y() / P_c.z() + s.right.cy);
  const ReprojectionFactor factor(s.bearing, s.left.T_b_c, s.right, px, 1.0);
  const double* params[] = {s.blocks[0].data(), s.blocks[1].data(), s.blocks[2].data()};
  Eigen::Vector2d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  // A point behind the observer is rejected, not projected.
  std::vector<double> negative = {-0.1};
  const double* bad[] = {s.blocks[0].data(), s.blocks[1].data(), negative.data()};
  EXPECT_FALSE(factor.Evaluate(bad, r.data(), nullptr));
}

TEST(SameFrameReprojectionFactor, StereoDisparityAndJacobian) {
  const ReprojectionSetup s = makeReprojectionSetup();
  // A point at depth Z straight ahead appears fx * b / Z pixels to the left in the right image.
  const double depth = 12.0;
  const Eigen::Vector2d px_right(s.left.cx - s.left.fx * 0.537 / depth, s.left.cy);
  const SameFrameReprojectionFactor factor(Eigen::Vector3d(0, 0, 1), s.left.T_b_c, s.right,
                                           px_right, 1.0);
  std::vector<std::vector<double>> blocks = {{1.0 / depth}};
  const double* params[] = {blocks[0].data()};
  Eigen::Vector2d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  blocks[0][0] = 1.0 / 9.0;
  const auto num = numericTangentJacobian<2>(factor, blocks, 0, false);
  const auto ana = analyticTangentJacobian<2>(factor, blocks, 0, false);
  EXPECT_LT((num - ana).norm(), 1e-6 * std::max(1.0, ana.norm()));
}

// Time-offset factors (Qin and Shen 2018): the analytic t_d column and the rest match central
// differences; at t_d = 0 they are the plain factors; the true t_d zeroes the residual of a point
// whose observations were taken t_d before their stamps.
TEST(ReprojectionTimeOffsetFactor, JacobiansMatchNumericDerivatives) {
  const ReprojectionSetup s = makeReprojectionSetup();
  std::vector<std::vector<double>> blocks = s.blocks;
  blocks.push_back({0.013});
  const Eigen::Vector2d anchor_px(s.left.fx * s.bearing.x() + s.left.cx,
                                  s.left.fy * s.bearing.y() + s.left.cy);
  const MovingPixel anchor{anchor_px, Eigen::Vector2d(-120.0, 35.0)};
  for (const PinholeView* observer : {&s.left, &s.right}) {
    const ReprojectionTimeOffsetFactor factor(anchor, s.left, *observer,
                                              {Eigen::Vector2d(650.0, 170.0), {-90.0, 20.0}}, 1.5);
    for (std::size_t b = 0; b < 4; ++b) {
      const bool is_pose = b < 2;
      const auto num = numericTangentJacobian<2>(factor, blocks, b, is_pose);
      const auto ana = analyticTangentJacobian<2>(factor, blocks, b, is_pose);
      EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << b;
    }
  }
  // At t_d = 0 the plain factor: same residual, same Jacobians.
  blocks[3][0] = 0.0;
  const ReprojectionTimeOffsetFactor with_td(anchor, s.left, s.right,
                                             {Eigen::Vector2d(650.0, 170.0), {-90.0, 20.0}}, 1.5);
  const ReprojectionFactor plain(s.bearing, s.left.T_b_c, s.right, Eigen::Vector2d(650.0, 170.0),
                                 1.5);
  for (std::size_t b = 0; b < 3; ++b) {
    EXPECT_LT((analyticTangentJacobian<2>(with_td, blocks, b, b < 2) -
               analyticTangentJacobian<2>(plain, s.blocks, b, b < 2))
                  .norm(),
              1e-12)
        << b;
  }
}

TEST(ReprojectionTimeOffsetFactor, TheTrueOffsetExplainsObservationsTakenBeforeTheirStamps) {
  const ReprojectionSetup s = makeReprojectionSetup();
  const auto project = [](const PinholeView& cam, const Eigen::Isometry3d& T_w_b,
                          const Eigen::Vector3d& P_w) {
    const Eigen::Vector3d P_c = (T_w_b * cam.T_b_c).inverse() * P_w;
    return Eigen::Vector2d(cam.fx * P_c.x() / P_c.z() + cam.cx,
                           cam.fy * P_c.y() / P_c.z() + cam.cy);
  };
  const Eigen::Isometry3d T_i = poseFromBlock(s.blocks[0].data());
  const Eigen::Isometry3d T_j = poseFromBlock(s.blocks[1].data());
  const Eigen::Vector3d P_w = T_i * s.left.T_b_c * (s.bearing / s.blocks[2][0]);
  // The poses are at the stamps; the images were exposed t_d earlier, while the point moved
  // across the image at these velocities.
  const double t_d = 0.02;
  const Eigen::Vector2d v_i(-150.0, 40.0), v_j(-80.0, 25.0);
  const MovingPixel anchor{project(s.left, T_i, P_w) - t_d * v_i, v_i};
  const MovingPixel seen{project(s.right, T_j, P_w) - t_d * v_j, v_j};
  const ReprojectionTimeOffsetFactor factor(anchor, s.left, s.right, seen, 1.0);
  std::vector<double> offset = {t_d};
  const double* params[] = {s.blocks[0].data(), s.blocks[1].data(), s.blocks[2].data(),
                            offset.data()};
  Eigen::Vector2d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  offset[0] = 0.0;  // ignoring the offset leaves pixels of error
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_GT(r.norm(), 1.0);
}

TEST(SameFrameTimeOffsetFactor, JacobiansMatchNumericDerivatives) {
  const ReprojectionSetup s = makeReprojectionSetup();
  const double depth = 12.0;
  const MovingPixel anchor{Eigen::Vector2d(s.left.cx + 40.0, s.left.cy - 10.0), {-60.0, 5.0}};
  const MovingPixel right{
      Eigen::Vector2d(s.left.cx + 40.0 - s.left.fx * 0.537 / depth, s.left.cy - 10.0),
      {-55.0, 5.0}};
  const SameFrameTimeOffsetFactor factor(anchor, s.left, s.right, right, 1.0);
  std::vector<std::vector<double>> blocks = {{1.0 / depth}, {0.0}};
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Vector2d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);  // t_d = 0: the plain stereo residual
  blocks = {{1.0 / 9.0}, {0.03}};
  for (std::size_t b = 0; b < 2; ++b) {
    const auto num = numericTangentJacobian<2>(factor, blocks, b, false);
    const auto ana = analyticTangentJacobian<2>(factor, blocks, b, false);
    EXPECT_LT((num - ana).norm(), 1e-6 * std::max(1.0, ana.norm())) << b;
  }
}

TEST(PosePriorFactor, JacobianAndWorldFrameSigmas) {
  std::mt19937 rng(5);
  const std::array<double, 7> x0 = randomPose(rng, 4.0);
  PoseSigmas sigmas;
  sigmas.tilt_rad = 0.01;
  sigmas.yaw_rad = 0.5;
  sigmas.position_m = 2.0;
  const PosePriorFactor factor(x0.data(), sigmas);
  std::vector<std::vector<double>> blocks = {std::vector<double>(x0.begin(), x0.end())};
  const double* params[] = {blocks[0].data()};
  Eigen::Matrix<double, 6, 1> r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
  // A yaw of 0.1 rad about the world vertical costs 0.1 / 0.5; the same tilt costs 0.1 / 0.01.
  const Eigen::Isometry3d T0 = poseFromBlock(x0.data());
  for (const auto& [axis, sigma] : {std::pair{Eigen::Vector3d::UnitZ().eval(), 0.5},
                                    std::pair{Eigen::Vector3d::UnitX().eval(), 0.01}}) {
    Eigen::Isometry3d T = T0;
    T.linear() = expSo3(0.1 * axis) * T0.linear();
    poseToBlock(T, blocks[0].data());
    ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
    EXPECT_NEAR(r.norm(), 0.1 / sigma, 1e-6 / sigma);
  }
  Vector6d delta;
  delta << 0.2, -0.1, 0.3, 1.0, -2.0, 0.5;
  PoseManifold manifold;
  manifold.Plus(x0.data(), delta.data(), blocks[0].data());
  const auto num = numericTangentJacobian<6>(factor, blocks, 0, true);
  const auto ana = analyticTangentJacobian<6>(factor, blocks, 0, true);
  EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm()));
}

}  // namespace
}  // namespace gvio::odometry
