#include "odometry/prior_factor.hpp"

#include <algorithm>

#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::odometry {

PosePriorFactor::PosePriorFactor(const double* pose0, const PoseSigmas& sigmas) {
  std::copy(pose0, pose0 + 7, pose0_.begin());
  const Eigen::Matrix3d R0 = poseQ(pose0).normalized().toRotationMatrix();
  // Minus(x, x0) = (Log(R0^T R), R0^T (p - p0)) lives in the body frame of x0; R0 takes both parts
  // to the world frame, where the sigmas are stated.
  const Eigen::Vector3d rot_w(1.0 / sigmas.tilt_rad, 1.0 / sigmas.tilt_rad, 1.0 / sigmas.yaw_rad);
  sqrt_information_.setZero();
  sqrt_information_.topLeftCorner<3, 3>() = rot_w.asDiagonal() * R0;
  sqrt_information_.bottomRightCorner<3, 3>() = (1.0 / sigmas.position_m) * R0;
}

bool PosePriorFactor::Evaluate(double const* const* parameters, double* residuals,
                               double** jacobians) const {
  const Eigen::Matrix3d R0 = poseQ(pose0_.data()).normalized().toRotationMatrix();
  const Eigen::Matrix3d R = poseQ(parameters[0]).normalized().toRotationMatrix();
  const Eigen::Vector3d phi = logSo3(R0.transpose() * R);
  Eigen::Matrix<double, 6, 1> e;
  e << phi, R0.transpose() * (poseP(parameters[0]) - poseP(pose0_.data()));
  Eigen::Map<Eigen::Matrix<double, 6, 1>>{residuals} = sqrt_information_ * e;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    // d Log(R0^T R Exp(dphi)) = Jr^-1(phi) dphi;  d R0^T (p + R dp) = R0^T R dp.
    Eigen::Matrix<double, 6, 6> J_t = Eigen::Matrix<double, 6, 6>::Zero();
    J_t.topLeftCorner<3, 3>() = rightJacobianInverseSo3(phi);
    J_t.bottomRightCorner<3, 3>() = R0.transpose() * R;
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>>{jacobians[0]} =
        sqrt_information_ * J_t * poseMinusJacobian(parameters[0]);
  }
  return true;
}

}  // namespace gvio::odometry
