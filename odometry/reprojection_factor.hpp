#pragma once
// Reprojection residuals of a landmark parameterised by its inverse depth rho in the camera that
// first observed it (the anchor; VINS-Mono, Qin et al. 2018, section VI-B; Civera et al. 2008):
//   P_ca = u_a / rho,  u_a = (x, y, 1) the anchor bearing on the normalised image plane,
//   P_w = R_i (R_b_ca P_ca + t_b_ca) + p_i,   P_co = R_b_co^T (R_j^T (P_w - p_j) - t_b_co),
//   r = (f_x X/Z + c_x - u, f_y Y/Z + c_y - v) / sigma_px      (pixels, whitened).
// Analytic Jacobians in the PoseManifold tangent (dphi, dp) of pose_i and pose_j.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvio::odometry {

// Pinhole intrinsics of a rectified camera and its pose in the body.
struct PinholeView {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
};

// Observation in another frame j (pose_i != pose_j). Blocks: pose_i (7), pose_j (7), rho (1).
class ReprojectionFactor final : public ceres::SizedCostFunction<2, 7, 7, 1> {
 public:
  ReprojectionFactor(const Eigen::Vector3d& bearing_anchor, const Eigen::Isometry3d& T_b_ca,
                     const PinholeView& observer, const Eigen::Vector2d& px_observed,
                     double sigma_px);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d bearing_;
  Eigen::Isometry3d T_b_ca_;
  PinholeView observer_;
  Eigen::Vector2d px_;
  double inv_sigma_;
};

// Observation by another camera of the anchor's own frame (the right image of a stereo pair):
// depends on rho only. P_co = T_c_o_a P_ca with T_co_ca = T_b_co^-1 T_b_ca.
class SameFrameReprojectionFactor final : public ceres::SizedCostFunction<2, 1> {
 public:
  SameFrameReprojectionFactor(const Eigen::Vector3d& bearing_anchor,
                              const Eigen::Isometry3d& T_b_ca, const PinholeView& observer,
                              const Eigen::Vector2d& px_observed, double sigma_px);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d bearing_;
  Eigen::Isometry3d T_co_ca_;
  PinholeView observer_;
  Eigen::Vector2d px_;
  double inv_sigma_;
};

// The residual of anchor bearing u_a (inverse depth rho, in camera T_b_ca of pose_i) seen at
// `px` by `observer` of pose_j, with the 2x7 pose Jacobians (each optional, row-major) and
// J_ca = d r / d P_ca (optional) for chain rules through the anchor point. False when the point is
// behind a camera or rho <= 0.
bool anchoredResidual(const Eigen::Vector3d& u_a, const Eigen::Isometry3d& T_b_ca,
                      const PinholeView& observer, const Eigen::Vector2d& px, double inv_sigma,
                      double const* pose_i, double const* pose_j, double rho, double* residuals,
                      double* J_pose_i, double* J_pose_j, Eigen::Matrix<double, 2, 3>* J_ca);

// Whitened pixel residual of P_c and its 2x3 Jacobian d r / d P_c (rows scaled by inv_sigma).
// Returns false when the point is not in front of the camera (Z <= 1e-6).
bool projectResidual(const PinholeView& cam, const Eigen::Vector3d& P_c, const Eigen::Vector2d& px,
                     double inv_sigma, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 3>* J);

}  // namespace gvio::odometry
