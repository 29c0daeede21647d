#include "odometry/reprojection_factor.hpp"

#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::odometry {
namespace {

using Jac2x7 = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;
constexpr double kMinZ = 1e-6;

}  // namespace

bool projectResidual(const PinholeView& cam, const Eigen::Vector3d& P_c, const Eigen::Vector2d& px,
                     double inv_sigma, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 3>* J) {
  const double z = P_c.z();
  // Behind the camera the projection is meaningless; Ceres treats a false return as an invalid
  // step and shrinks the trust region instead of following it.
  if (!(z > kMinZ)) return false;
  const double inv_z = 1.0 / z;
  r = inv_sigma * Eigen::Vector2d(cam.fx * P_c.x() * inv_z + cam.cx - px.x(),
                                  cam.fy * P_c.y() * inv_z + cam.cy - px.y());
  if (J != nullptr) {
    *J << cam.fx * inv_z, 0.0, -cam.fx * P_c.x() * inv_z * inv_z,  //
        0.0, cam.fy * inv_z, -cam.fy * P_c.y() * inv_z * inv_z;
    *J *= inv_sigma;
  }
  return true;
}

ReprojectionFactor::ReprojectionFactor(const Eigen::Vector3d& bearing_anchor,
                                       const Eigen::Isometry3d& T_b_ca, const PinholeView& observer,
                                       const Eigen::Vector2d& px_observed, double sigma_px)
    : bearing_(bearing_anchor),
      T_b_ca_(T_b_ca),
      observer_(observer),
      px_(px_observed),
      inv_sigma_(1.0 / sigma_px) {}

bool anchoredResidual(const Eigen::Vector3d& u_a, const Eigen::Isometry3d& T_b_ca,
                      const PinholeView& observer, const Eigen::Vector2d& px, double inv_sigma,
                      double const* pose_i, double const* pose_j, double rho, double* residuals,
                      double* J_pose_i, double* J_pose_j, Eigen::Matrix<double, 2, 3>* J_ca) {
  const Eigen::Matrix3d R_i = poseQ(pose_i).normalized().toRotationMatrix();
  const Eigen::Vector3d p_i = poseP(pose_i);
  const Eigen::Matrix3d R_j = poseQ(pose_j).normalized().toRotationMatrix();
  const Eigen::Vector3d p_j = poseP(pose_j);
  if (!(rho > 0.0)) return false;

  const Eigen::Vector3d P_ca = u_a / rho;
  const Eigen::Vector3d P_bi = T_b_ca * P_ca;
  const Eigen::Vector3d P_w = R_i * P_bi + p_i;
  const Eigen::Vector3d P_bj = R_j.transpose() * (P_w - p_j);
  const Eigen::Matrix3d R_co_b = observer.T_b_c.rotation().transpose();
  const Eigen::Vector3d P_co = R_co_b * (P_bj - observer.T_b_c.translation());

  // A cost-only evaluation (Ceres' candidate steps, about half of them) skips the Jacobians.
  const bool jacobians = J_pose_i != nullptr || J_pose_j != nullptr || J_ca != nullptr;
  Eigen::Vector2d r_value;
  Eigen::Matrix<double, 2, 3> J_proj;
  if (!projectResidual(observer, P_co, px, inv_sigma, r_value, jacobians ? &J_proj : nullptr)) {
    return false;
  }
  Eigen::Map<Eigen::Vector2d>{residuals} = r_value;
  if (!jacobians) return true;

  // Chain rule through P_co = R_co_b R_j^T (P_w - p_j) - ...; perturbations R Exp(dphi), p + R dp.
  const Eigen::Matrix<double, 2, 3> J_w = J_proj * R_co_b * R_j.transpose();
  if (J_pose_i != nullptr) {
    Eigen::Matrix<double, 2, 6> J_t;
    J_t << -J_w * R_i * hat(P_bi), J_w * R_i;  // dP_w/dphi_i = -R_i hat(P_bi), dP_w/dp_i = R_i
    Eigen::Map<Jac2x7>{J_pose_i} = J_t * poseMinusJacobian(pose_i);
  }
  if (J_pose_j != nullptr) {
    Eigen::Matrix<double, 2, 6> J_t;
    const Eigen::Matrix<double, 2, 3> J_bj = J_proj * R_co_b;
    J_t << J_bj * hat(P_bj), -J_bj;  // dP_bj/dphi_j = hat(P_bj), dP_bj/dp_j = -I
    Eigen::Map<Jac2x7>{J_pose_j} = J_t * poseMinusJacobian(pose_j);
  }
  if (J_ca != nullptr) *J_ca = J_w * R_i * T_b_ca.rotation();
  return true;
}

bool ReprojectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const double rho = parameters[2][0];
  Eigen::Matrix<double, 2, 3> J_ca;
  const bool want = jacobians != nullptr;
  if (!anchoredResidual(bearing_, T_b_ca_, observer_, px_, inv_sigma_, parameters[0], parameters[1],
                        rho, residuals, want ? jacobians[0] : nullptr,
                        want ? jacobians[1] : nullptr, want ? &J_ca : nullptr)) {
    return false;
  }
  if (want && jacobians[2] != nullptr) {
    // dP_ca/drho = -u_a / rho^2.
    Eigen::Map<Eigen::Vector2d>{jacobians[2]} = J_ca * (-bearing_ / (rho * rho));
  }
  return true;
}

SameFrameReprojectionFactor::SameFrameReprojectionFactor(const Eigen::Vector3d& bearing_anchor,
                                                         const Eigen::Isometry3d& T_b_ca,
                                                         const PinholeView& observer,
                                                         const Eigen::Vector2d& px_observed,
                                                         double sigma_px)
    : bearing_(bearing_anchor),
      T_co_ca_(observer.T_b_c.inverse() * T_b_ca),
      observer_(observer),
      px_(px_observed),
      inv_sigma_(1.0 / sigma_px) {}

bool SameFrameReprojectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  const double rho = parameters[0][0];
  if (!(rho > 0.0)) return false;
  const Eigen::Vector3d P_co = T_co_ca_ * (bearing_ / rho);
  Eigen::Vector2d r_value;
  Eigen::Matrix<double, 2, 3> J_proj;
  if (!projectResidual(observer_, P_co, px_, inv_sigma_, r_value, &J_proj)) return false;
  Eigen::Map<Eigen::Vector2d>{residuals} = r_value;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Vector2d>{jacobians[0]} =
        J_proj * T_co_ca_.rotation() * (-bearing_ / (rho * rho));
  }
  return true;
}

}  // namespace gvio::odometry
