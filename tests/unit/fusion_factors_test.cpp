// Jacobians of the GNSS fusion graph's factors against central differences through the pose
// manifold, and their zero residual at the true state.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_factors.hpp"
#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"
#include "support/ceres_jacobian.hpp"

namespace gvio::fusion {
namespace {

using test::analyticTangentJacobian;
using test::numericTangentJacobian;
using test::poseBlock;

TEST(RelativePoseFactor, ZeroAtTheMeasurementAndJacobians) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.1, -0.2, 1.3), Eigen::Vector3d(10, -5, 2)),
      poseBlock(Eigen::Vector3d(0.05, 0.1, 1.6), Eigen::Vector3d(14, -2, 2.5))};
  const Eigen::Isometry3d T_i = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Isometry3d T_j = odometry::poseFromBlock(blocks[1].data());
  const RelativePoseFactor exact(T_i.inverse() * T_j, 0.01, 0.1);
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Matrix<double, 6, 1> r;
  ASSERT_TRUE(exact.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  Eigen::Isometry3d noisy = T_i.inverse() * T_j;
  noisy.translation() += Eigen::Vector3d(0.3, -0.1, 0.2);
  noisy.linear() = noisy.linear() * odometry::expSo3(Eigen::Vector3d(0.02, 0.05, -0.03));
  const RelativePoseFactor factor(noisy, 0.01, 0.1);
  for (std::size_t b = 0; b < 2; ++b) {
    const auto num = numericTangentJacobian<6>(factor, blocks, b, true);
    const auto ana = analyticTangentJacobian<6>(factor, blocks, b, true);
    EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << b;
  }
}

TEST(GnssPositionFactor, ZeroAtTheAntennaAndJacobian) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.02, -0.01, 2.0), Eigen::Vector3d(100, 50, 3))};
  const Eigen::Isometry3d T = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Vector3d q_b(1.2, 0.3, 1.5);
  const Eigen::Matrix3d W = gnssSqrtInformation(1.5, 3.0, Eigen::Matrix2d::Identity());
  const GnssPositionFactor exact(q_b, T * q_b, W);
  const double* params[] = {blocks[0].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(exact.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  const GnssPositionFactor off(q_b, T * q_b + Eigen::Vector3d(1.5, 0.0, 3.0), W);
  ASSERT_TRUE(off.Evaluate(params, r.data(), nullptr));
  EXPECT_LT((r - Eigen::Vector3d(-1, 0, -1)).norm(), 1e-9);  // whitened per axis
  const auto num = numericTangentJacobian<3>(off, blocks, 0, true);
  const auto ana = analyticTangentJacobian<3>(off, blocks, 0, true);
  EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm()));
}

// A fix with a stated ellipse (a full square-root information W): r = W e, and its Jacobians.
TEST(GnssPositionFactor, FullSqrtInformationWhitensAndJacobians) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.02, -0.01, 2.0), Eigen::Vector3d(100, 50, 3)), {0.7, -0.4, 1.1}};
  const Eigen::Isometry3d T = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Vector3d q_b(1.2, 0.3, 1.5);
  const Eigen::Vector3d b(blocks[1][0], blocks[1][1], blocks[1][2]);
  const Eigen::Matrix3d W =
      gnssSqrtInformation(2.0, 4.0, horizontalShape(ellipseCovariance(3.0, 0.8, 35.0)));
  const Eigen::Vector3d e(1.5, -0.7, 3.0);
  const GnssPositionFactor plain(q_b, T * q_b + e, W);
  const GnssBiasedPositionFactor biased(q_b, T * q_b + b + e, W);
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(plain.Evaluate(params, r.data(), nullptr));
  EXPECT_LT((r + W * e).norm(), 1e-9);
  ASSERT_TRUE(biased.Evaluate(params, r.data(), nullptr));
  EXPECT_LT((r + W * e).norm(), 1e-9);
  std::vector<std::vector<double>> pose_only = {blocks[0]};
  const auto num = numericTangentJacobian<3>(plain, pose_only, 0, true);
  const auto ana = analyticTangentJacobian<3>(plain, pose_only, 0, true);
  EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm()));
  for (std::size_t k = 0; k < 2; ++k) {
    const auto num_b = numericTangentJacobian<3>(biased, blocks, k, k == 0);
    const auto ana_b = analyticTangentJacobian<3>(biased, blocks, k, k == 0);
    EXPECT_LT((num_b - ana_b).norm(), 1e-5 * std::max(1.0, ana_b.norm())) << "block " << k;
  }
}

TEST(GnssBiasedPositionFactor, ZeroAtTheBiasedAntennaAndJacobians) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.02, -0.01, 2.0), Eigen::Vector3d(100, 50, 3)), {0.7, -0.4, 1.1}};
  const Eigen::Isometry3d T = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Vector3d q_b(1.2, 0.3, 1.5);
  const Eigen::Vector3d b(blocks[1][0], blocks[1][1], blocks[1][2]);
  const Eigen::Matrix3d W = gnssSqrtInformation(1.5, 3.0, Eigen::Matrix2d::Identity());
  const GnssBiasedPositionFactor exact(q_b, T * q_b + b, W);
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(exact.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  const GnssBiasedPositionFactor off(q_b, T * q_b + b + Eigen::Vector3d(1.5, 0.0, 3.0), W);
  ASSERT_TRUE(off.Evaluate(params, r.data(), nullptr));
  EXPECT_LT((r - Eigen::Vector3d(-1, 0, -1)).norm(), 1e-9);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto num = numericTangentJacobian<3>(off, blocks, k, k == 0);
    const auto ana = analyticTangentJacobian<3>(off, blocks, k, k == 0);
    EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << k;
  }
}

TEST(GaussMarkovFactor, WhitensTheProcessNoiseAndJacobians) {
  // dt = tau: phi = 1/e, var(w) = sigma^2 (1 - e^-2).
  const GaussMarkovFactor factor(30.0, 30.0, 2.0);
  std::vector<std::vector<double>> blocks = {{1.0, -2.0, 0.5}, {0.3, 0.1, -0.4}};
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  const double phi = std::exp(-1.0), sigma_w = 2.0 * std::sqrt(1.0 - phi * phi);
  const Eigen::Vector3d expected =
      (Eigen::Vector3d(0.3, 0.1, -0.4) - phi * Eigen::Vector3d(1.0, -2.0, 0.5)) / sigma_w;
  EXPECT_LT((r - expected).norm(), 1e-12);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto num = numericTangentJacobian<3>(factor, blocks, k, false);
    const auto ana = analyticTangentJacobian<3>(factor, blocks, k, false);
    EXPECT_LT((num - ana).norm(), 1e-6 * std::max(1.0, ana.norm())) << "block " << k;
  }
}

// With the fix's ellipse the driving noise is shaped horizontally: r = W (b_j - phi b_i).
TEST(GaussMarkovFactor, ShapedByTheEllipseAndJacobians) {
  const Eigen::Matrix2d shape = horizontalShape(ellipseCovariance(3.0, 1.0, 60.0));
  const GaussMarkovFactor factor(30.0, 30.0, 2.0, shape);
  std::vector<std::vector<double>> blocks = {{1.0, -2.0, 0.5}, {0.3, 0.1, -0.4}};
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  const double phi = std::exp(-1.0), sigma_w = 2.0 * std::sqrt(1.0 - phi * phi);
  const Eigen::Vector3d w = Eigen::Vector3d(0.3, 0.1, -0.4) - phi * Eigen::Vector3d(1.0, -2.0, 0.5);
  const Eigen::Matrix3d cov = gnssCovariance(sigma_w, sigma_w, shape);
  EXPECT_NEAR(r.squaredNorm(), w.dot(cov.inverse() * w), 1e-12);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto num = numericTangentJacobian<3>(factor, blocks, k, false);
    const auto ana = analyticTangentJacobian<3>(factor, blocks, k, false);
    EXPECT_LT((num - ana).norm(), 1e-6 * std::max(1.0, ana.norm())) << "block " << k;
  }
}

}  // namespace
}  // namespace gvio::fusion
