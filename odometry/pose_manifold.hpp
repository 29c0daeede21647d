#pragma once
// Pose parameter block for Ceres: ambient [qx qy qz qw px py pz] (Eigen quaternion order, then the
// body position in the world), tangent (dphi, dp) with the right/body-side perturbation used by the
// IMU preintegration paper (Forster et al. 2017, eq. 65ff.):
//   Plus(x, (dphi, dp)) = (q Exp(dphi), p + R(q) dp).
// Residuals compute their Jacobians J_t in this tangent space and hand Ceres the ambient Jacobian
// J_t * MinusJacobian(x); since MinusJacobian(x) * PlusJacobian(x) = I, Ceres' product with
// PlusJacobian gives back exactly J_t (the usual VINS/OKVIS construction, here with a manifold
// whose Plus/Minus Jacobians are the true ones).
#include <ceres/manifold.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvio::odometry {

inline constexpr int kPoseAmbient = 7;
inline constexpr int kPoseTangent = 6;

class PoseManifold final : public ceres::Manifold {
 public:
  [[nodiscard]] int AmbientSize() const override { return kPoseAmbient; }
  [[nodiscard]] int TangentSize() const override { return kPoseTangent; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

using PoseMinusJacobian = Eigen::Matrix<double, kPoseTangent, kPoseAmbient, Eigen::RowMajor>;
// d Minus(y, x) / dy at y = x (6x7), the factor that turns tangent Jacobians into ambient ones.
PoseMinusJacobian poseMinusJacobian(const double* x);

// Views of a pose block.
inline Eigen::Map<const Eigen::Quaterniond> poseQ(const double* x) {
  return Eigen::Map<const Eigen::Quaterniond>(x);
}
inline Eigen::Map<const Eigen::Vector3d> poseP(const double* x) {
  return Eigen::Map<const Eigen::Vector3d>(x + 4);
}
Eigen::Isometry3d poseFromBlock(const double* x);
// Writes T (rotation normalised) into a 7-double block.
void poseToBlock(const Eigen::Isometry3d& T, double* x);

}  // namespace gvio::odometry
