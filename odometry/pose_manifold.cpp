#include "odometry/pose_manifold.hpp"

#include <cmath>

#include "odometry/lie.hpp"

namespace gvio::odometry {
namespace {

// Unit quaternion of the rotation vector phi (exact half-angle formula, Taylor branch near 0).
Eigen::Quaterniond quaternionExp(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const double half = 0.5 * theta;
  const double k = theta < 1e-8 ? 0.5 - theta * theta / 48.0 : std::sin(half) / theta;
  return {std::cos(half), k * phi.x(), k * phi.y(), k * phi.z()};
}

}  // namespace

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Quaterniond q = poseQ(x);
  Eigen::Map<const Eigen::Vector3d> dphi(delta), dp(delta + 3);
  Eigen::Quaterniond q_new = (q * quaternionExp(dphi)).normalized();
  Eigen::Map<Eigen::Quaterniond>{x_plus_delta} = q_new;
  Eigen::Map<Eigen::Vector3d>{x_plus_delta + 4} = poseP(x) + q.toRotationMatrix() * dp;
  return true;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  // d(q (x) [dphi/2, 1]) / d dphi = 0.5 [qw I + hat(qv); -qv^T] (quaternion product, xyzw rows).
  const Eigen::Quaterniond q = poseQ(x);
  Eigen::Map<Eigen::Matrix<double, kPoseAmbient, kPoseTangent, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.block<3, 3>(0, 0) = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + hat(q.vec()));
  J.block<1, 3>(3, 0) = -0.5 * q.vec().transpose();
  J.block<3, 3>(4, 3) = q.toRotationMatrix();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  // Normalised, so that Minus ignores the (meaningless) scale of the ambient quaternions and its
  // ambient derivative is exactly MinusJacobian() in every direction.
  const Eigen::Matrix3d R_x = poseQ(x).normalized().toRotationMatrix();
  const Eigen::Matrix3d R_y = poseQ(y).normalized().toRotationMatrix();
  Eigen::Map<Eigen::Vector3d>{y_minus_x} = logSo3(R_x.transpose() * R_y);
  Eigen::Map<Eigen::Vector3d>{y_minus_x + 3} = R_x.transpose() * (poseP(y) - poseP(x));
  return true;
}

PoseMinusJacobian poseMinusJacobian(const double* x) {
  // d 2 vec(q_x^* (x) q_y) / d q_y at q_y = q_x = 2 [qw I - hat(qv), -qv]; d R_x^T (p_y - p_x) / d
  // p_y = R_x^T.
  const Eigen::Quaterniond q = poseQ(x);
  PoseMinusJacobian J = PoseMinusJacobian::Zero();
  J.block<3, 3>(0, 0) = 2.0 * (q.w() * Eigen::Matrix3d::Identity() - hat(q.vec()));
  J.block<3, 1>(0, 3) = -2.0 * q.vec();
  J.block<3, 3>(3, 4) = q.toRotationMatrix().transpose();
  return J;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<PoseMinusJacobian>{jacobian} = poseMinusJacobian(x);
  return true;
}

Eigen::Isometry3d poseFromBlock(const double* x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = poseQ(x).normalized().toRotationMatrix();
  T.translation() = poseP(x);
  return T;
}

void poseToBlock(const Eigen::Isometry3d& T, double* x) {
  Eigen::Map<Eigen::Quaterniond>{x} = Eigen::Quaterniond(T.rotation()).normalized();
  Eigen::Map<Eigen::Vector3d>{x + 4} = T.translation();
}

}  // namespace gvio::odometry
