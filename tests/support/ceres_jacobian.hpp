#pragma once
// Jacobian checks for Ceres cost functions on the estimator's blocks: central differences of
// r(Plus(x, delta)) against the analytic ambient Jacobian times the manifold's PlusJacobian (what
// Ceres itself uses). Pose blocks use odometry::PoseManifold, other blocks are Euclidean.
#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <vector>

#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::test {

// A pose block (odometry/pose_manifold.hpp) of the rotation Exp(phi) and position p.
inline std::vector<double> poseBlock(const Eigen::Vector3d& phi, const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = odometry::expSo3(phi);
  T.translation() = p;
  std::vector<double> x(odometry::kPoseAmbient);
  odometry::poseToBlock(T, x.data());
  return x;
}

// d r(Plus(x, delta)) / d delta, for block `b` of a cost function.
template <int R>
Eigen::Matrix<double, R, Eigen::Dynamic> numericTangentJacobian(
    const ceres::CostFunction& f, std::vector<std::vector<double>> blocks, std::size_t b,
    bool is_pose) {
  odometry::PoseManifold manifold;
  const int dim = is_pose ? 6 : static_cast<int>(blocks[b].size());
  Eigen::Matrix<double, R, Eigen::Dynamic> J(R, dim);
  const double h = 1e-6;
  for (int c = 0; c < dim; ++c) {
    Eigen::Matrix<double, R, 1> rp, rm;
    for (int sign : {1, -1}) {
      std::vector<std::vector<double>> moved = blocks;
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(dim);
      delta(c) = sign * h;
      if (is_pose) {
        manifold.Plus(blocks[b].data(), delta.data(), moved[b].data());
      } else {
        moved[b][static_cast<std::size_t>(c)] += sign * h;
      }
      std::vector<const double*> ptrs;
      for (const auto& m : moved) ptrs.push_back(m.data());
      Eigen::Matrix<double, R, 1>& out = sign > 0 ? rp : rm;
      EXPECT_TRUE(f.Evaluate(ptrs.data(), out.data(), nullptr));
    }
    J.col(c) = (rp - rm) / (2.0 * h);
  }
  return J;
}

// Analytic ambient Jacobian times PlusJacobian (what Ceres uses) for block b.
template <int R>
Eigen::Matrix<double, R, Eigen::Dynamic> analyticTangentJacobian(
    const ceres::CostFunction& f, const std::vector<std::vector<double>>& blocks, std::size_t b,
    bool is_pose) {
  std::vector<const double*> ptrs;
  for (const auto& m : blocks) ptrs.push_back(m.data());
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> jac;
  std::vector<double*> jac_ptrs;
  for (const auto& m : blocks) {
    jac.emplace_back(R, static_cast<int>(m.size()));
  }
  for (auto& j : jac) jac_ptrs.push_back(j.data());
  Eigen::Matrix<double, R, 1> r;
  EXPECT_TRUE(f.Evaluate(ptrs.data(), r.data(), jac_ptrs.data()));
  if (!is_pose) return jac[b];
  odometry::PoseManifold manifold;
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
  manifold.PlusJacobian(blocks[b].data(), plus.data());
  return jac[b] * plus;
}

}  // namespace gvio::test
