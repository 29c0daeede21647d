#pragma once
// SO(3) helpers for IMU preintegration and the estimator's residuals, following Forster, Carlone,
// Dellaert, Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial Odometry",
// IEEE T-RO 2017 (equation numbers below refer to that paper). Rotation vectors phi are in
// radians; perturbations are applied on the right: R Exp(dphi).
#include <Eigen/Core>

namespace gvio::odometry {

// Skew-symmetric matrix: hat(w) v = w x v (eq. 2).
Eigen::Matrix3d hat(const Eigen::Vector3d& w);

// Inverse of hat: the vector of a skew-symmetric matrix (the skew part only, for any 3x3 input).
Eigen::Vector3d vee(const Eigen::Matrix3d& W);

// Exponential map so(3) -> SO(3), Rodrigues' formula (eq. 3) with a Taylor branch near 0.
Eigen::Matrix3d expSo3(const Eigen::Vector3d& phi);

// Logarithm map SO(3) -> so(3) (eq. 5), returning the rotation vector with angle in [0, pi].
// Accurate near 0 (Taylor branch) and near pi (axis from the symmetric part of R).
Eigen::Vector3d logSo3(const Eigen::Matrix3d& R);

// Right Jacobian Jr(phi) (eq. 8): Exp(phi + dphi) ~= Exp(phi) Exp(Jr(phi) dphi).
Eigen::Matrix3d rightJacobianSo3(const Eigen::Vector3d& phi);

// Inverse right Jacobian Jr^-1(phi) (eq. 9): Log(Exp(phi) Exp(dphi)) ~= phi + Jr^-1(phi) dphi.
// Singular only at |phi| = 2 pi; Log never returns such angles.
Eigen::Matrix3d rightJacobianInverseSo3(const Eigen::Vector3d& phi);

// The rotation nearest to M in the Frobenius norm (SVD projection, determinant +1), to remove the
// drift of long products of rotation matrices.
Eigen::Matrix3d normalizeRotation(const Eigen::Matrix3d& M);

// ZYX Euler angles (roll, pitch, yaw; radians): R = Rz(yaw) Ry(pitch) Rx(roll), and back (pitch
// within +-90 deg).
Eigen::Matrix3d rotationZyx(const Eigen::Vector3d& rpy);
Eigen::Vector3d eulerZyx(const Eigen::Matrix3d& R);

}  // namespace gvio::odometry
