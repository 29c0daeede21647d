#include "odometry/lie.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "support/numeric_jacobian.hpp"

namespace gvio::odometry {
namespace {

constexpr double kPi = std::numbers::pi;

// Unit axes spread over the sphere, deterministic.
std::vector<Eigen::Vector3d> axes(int count) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> result;
  for (int i = 0; i < count; ++i) {
    result.emplace_back(Eigen::Vector3d{normal(rng), normal(rng), normal(rng)}.normalized());
  }
  return result;
}

// Angles from 0 to pi, dense near both ends where Exp and Log switch branches.
const std::vector<double> kAngles = {
    0.0, 1e-12, 1e-8,       1e-5,         1e-4,       9e-3,       1.1e-2,      0.3, 1.0,
    2.0, 3.0,   kPi - 2e-2, kPi - 0.9e-2, kPi - 1e-4, kPi - 1e-7, kPi - 1e-10, kPi};

Eigen::Matrix3d angleAxis(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

TEST(LieSo3, HatIsTheCrossProductAndVeeInvertsIt) {
  const Eigen::Vector3d w(0.3, -1.2, 2.5), v(-0.7, 0.4, 1.1);
  EXPECT_LT((hat(w) * v - w.cross(v)).norm(), 1e-15);
  EXPECT_LT((hat(w) + hat(w).transpose()).norm(), 1e-15);
  EXPECT_EQ(vee(hat(w)), w);
}

TEST(LieSo3, ExpMatchesEigenAngleAxis) {
  for (const Eigen::Vector3d& axis : axes(20)) {
    for (const double angle : kAngles) {
      EXPECT_LT((expSo3(angle * axis) - angleAxis(angle, axis)).norm(), 1e-14) << angle;
    }
  }
  EXPECT_EQ(expSo3(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
}

TEST(LieSo3, ExpOfLogIsIdentityIncludingNearZeroAndPi) {
  for (const Eigen::Vector3d& axis : axes(50)) {
    for (const double angle : kAngles) {
      const Eigen::Matrix3d R = angleAxis(angle, axis);
      EXPECT_LT((expSo3(logSo3(R)) - R).norm(), 1e-13) << "angle " << angle;
    }
  }
  // Random rotations from random unit quaternions.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond{normal(rng), normal(rng), normal(rng), normal(rng)}.normalized();
    const Eigen::Matrix3d R = q.toRotationMatrix();
    EXPECT_LT((expSo3(logSo3(R)) - R).norm(), 1e-13);
  }
}

TEST(LieSo3, LogOfExpIsIdentityBelowPi) {
  for (const Eigen::Vector3d& axis : axes(50)) {
    for (const double angle : kAngles) {
      const Eigen::Vector3d phi = angle * axis;
      const Eigen::Vector3d back = logSo3(expSo3(phi));
      if (angle < kPi) {
        EXPECT_LT((back - phi).norm(), 1e-12) << "angle " << angle;
      } else {  // Exp(pi a) = Exp(-pi a): either is a correct logarithm.
        EXPECT_LT(std::min((back - phi).norm(), (back + phi).norm()), 1e-12);
      }
    }
  }
}

TEST(LieSo3, LogNearPiKeepsFullPrecision) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  for (const double gap : {1e-3, 1e-6, 1e-9, 1e-12}) {
    const Eigen::Vector3d phi = (kPi - gap) * axis;
    EXPECT_LT((logSo3(angleAxis(kPi - gap, axis)) - phi).norm(), 1e-13) << gap;
  }
}

// Jr(phi) = d/d(dphi) Log(Exp(phi)^T Exp(phi + dphi)) at dphi = 0 (eq. 8).
TEST(LieSo3, RightJacobianMatchesCentralDifferences) {
  for (const Eigen::Vector3d& axis : axes(10)) {
    for (const double angle : {0.0, 1e-6, 1e-3, 9.9e-3, 1.01e-2, 0.5, 1.5, 2.5, 3.0}) {
      const Eigen::Vector3d phi = angle * axis;
      const Eigen::Matrix3d R_inv = expSo3(phi).transpose();
      const auto numeric = test::numericJacobian<3, 3>(
          [&](const Eigen::Vector3d& d) { return logSo3(R_inv * expSo3(phi + d)); });
      EXPECT_LT((numeric - rightJacobianSo3(phi)).cwiseAbs().maxCoeff(), 1e-6) << angle;
    }
  }
}

// Jr^-1(phi) = d/d(dphi) Log(Exp(phi) Exp(dphi)) at dphi = 0 (eq. 9).
TEST(LieSo3, InverseRightJacobianMatchesCentralDifferences) {
  for (const Eigen::Vector3d& axis : axes(10)) {
    for (const double angle : {0.0, 1e-6, 1e-3, 9.9e-3, 1.01e-2, 0.5, 1.5, 2.5, 3.0}) {
      const Eigen::Vector3d phi = angle * axis;
      const Eigen::Matrix3d R = expSo3(phi);
      const auto numeric = test::numericJacobian<3, 3>(
          [&](const Eigen::Vector3d& d) { return logSo3(R * expSo3(d)); });
      EXPECT_LT((numeric - rightJacobianInverseSo3(phi)).cwiseAbs().maxCoeff(), 1e-6) << angle;
    }
  }
}

TEST(LieSo3, InverseRightJacobianInvertsTheRightJacobian) {
  for (const Eigen::Vector3d& axis : axes(20)) {
    for (const double angle : kAngles) {
      const Eigen::Vector3d phi = angle * axis;
      const Eigen::Matrix3d product = rightJacobianInverseSo3(phi) * rightJacobianSo3(phi);
      EXPECT_LT((product - Eigen::Matrix3d::Identity()).norm(), 1e-12) << angle;
    }
  }
}

TEST(LieSo3, NormalizeRotationProjectsOntoSo3) {
  const Eigen::Matrix3d R = expSo3(Eigen::Vector3d(0.4, -1.1, 2.0));
  EXPECT_LT((normalizeRotation(R) - R).norm(), 1e-14);

  Eigen::Matrix3d drifted = R;
  drifted(0, 1) += 1e-6;
  drifted(2, 0) -= 2e-6;
  const Eigen::Matrix3d fixed = normalizeRotation(drifted);
  EXPECT_LT((fixed.transpose() * fixed - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(fixed.determinant(), 1.0, 1e-14);
  EXPECT_LT((fixed - R).norm(), 3e-6);

  // A reflection is mapped to a proper rotation, not to itself.
  const Eigen::Matrix3d reflection = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  EXPECT_NEAR(normalizeRotation(reflection).determinant(), 1.0, 1e-14);
}

}  // namespace
}  // namespace gvio::odometry
