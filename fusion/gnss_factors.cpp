#include "fusion/gnss_factors.hpp"

#include <algorithm>
#include <cmath>

#include <ceres/normal_prior.h>

#include "fusion/gnss_covariance.hpp"
#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::fusion {
namespace {

using odometry::hat;
using odometry::poseMinusJacobian;
using odometry::poseP;
using odometry::poseQ;

}  // namespace

RelativePoseFactor::RelativePoseFactor(const Eigen::Isometry3d& T_i_j, double sigma_rot_rad,
                                       double sigma_pos_m)
    : dR_(T_i_j.rotation()), dp_(T_i_j.translation()), sqrt_info_(Matrix6d::Zero()) {
  sqrt_info_.diagonal() << Eigen::Vector3d::Constant(1.0 / sigma_rot_rad),
      Eigen::Vector3d::Constant(1.0 / sigma_pos_m);
}

RelativePoseFactor::RelativePoseFactor(const Eigen::Isometry3d& T_i_j,
                                       const Matrix6d& sqrt_information)
    : dR_(T_i_j.rotation()), dp_(T_i_j.translation()), sqrt_info_(sqrt_information) {}

Eigen::Matrix<double, 6, 1> RelativePoseFactor::error(const Eigen::Isometry3d& T_i,
                                                      const Eigen::Isometry3d& T_j) const {
  const Eigen::Matrix3d R_i = T_i.rotation();
  Eigen::Matrix<double, 6, 1> e;
  e << odometry::logSo3(dR_.transpose() * R_i.transpose() * T_j.rotation()),
      R_i.transpose() * (T_j.translation() - T_i.translation()) - dp_;
  return e;
}

bool RelativePoseFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Matrix3d R_i = poseQ(parameters[0]).normalized().toRotationMatrix();
  const Eigen::Matrix3d R_j = poseQ(parameters[1]).normalized().toRotationMatrix();
  const Eigen::Vector3d a = R_i.transpose() * (poseP(parameters[1]) - poseP(parameters[0]));
  const Eigen::Vector3d r_rot = odometry::logSo3(dR_.transpose() * R_i.transpose() * R_j);
  Eigen::Matrix<double, 6, 1> e;
  e << r_rot, a - dp_;
  Eigen::Map<Eigen::Matrix<double, 6, 1>>{residuals} = sqrt_info_ * e;
  if (jacobians == nullptr) return true;
  const Eigen::Matrix3d Jr_inv = odometry::rightJacobianInverseSo3(r_rot);
  using Jac6x7 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    // d r_rot / d dphi_i = -Jr^-1 R_j^T R_i; d a / d dphi_i = hat(a); d a / d dp_i = -I.
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = -Jr_inv * R_j.transpose() * R_i;
    J.bottomLeftCorner<3, 3>() = hat(a);
    J.bottomRightCorner<3, 3>() = -Eigen::Matrix3d::Identity();
    Eigen::Map<Jac6x7>{jacobians[0]} = sqrt_info_ * J * poseMinusJacobian(parameters[0]);
  }
  if (jacobians[1] != nullptr) {
    // d r_rot / d dphi_j = Jr^-1; d a / d dp_j = R_i^T R_j.
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = Jr_inv;
    J.bottomRightCorner<3, 3>() = R_i.transpose() * R_j;
    Eigen::Map<Jac6x7>{jacobians[1]} = sqrt_info_ * J * poseMinusJacobian(parameters[1]);
  }
  return true;
}

GnssPositionFactor::GnssPositionFactor(const Eigen::Vector3d& q_b, const Eigen::Vector3d& p_enu_fix,
                                       const Eigen::Matrix3d& sqrt_information)
    : q_b_(q_b), p_fix_(p_enu_fix), sqrt_info_(sqrt_information) {}

bool GnssPositionFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Matrix3d R = poseQ(parameters[0]).normalized().toRotationMatrix();
  Eigen::Map<Eigen::Vector3d>{residuals} = sqrt_info_ * (poseP(parameters[0]) + R * q_b_ - p_fix_);
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    // d (R Exp(dphi) q) / d dphi = -R hat(q); d (p + R dp) / d dp = R.
    Eigen::Matrix<double, 3, 6> J;
    J << sqrt_info_ * (-R * hat(q_b_)), sqrt_info_ * R;
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>>{jacobians[0]} =
        J * poseMinusJacobian(parameters[0]);
  }
  return true;
}

GnssBiasedPositionFactor::GnssBiasedPositionFactor(const Eigen::Vector3d& q_b,
                                                   const Eigen::Vector3d& p_enu_fix,
                                                   const Eigen::Matrix3d& sqrt_information)
    : position_(q_b, p_enu_fix, sqrt_information) {}

bool GnssBiasedPositionFactor::Evaluate(double const* const* parameters, double* residuals,
                                        double** jacobians) const {
  double* pose_jacobian[1] = {jacobians != nullptr ? jacobians[0] : nullptr};
  position_.Evaluate(parameters, residuals, jacobians != nullptr ? pose_jacobian : nullptr);
  const Eigen::Map<const Eigen::Vector3d> b(parameters[1]);
  Eigen::Map<Eigen::Vector3d>{residuals} += position_.sqrtInformation() * b;
  if (jacobians != nullptr && jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{jacobians[1]} =
        position_.sqrtInformation();
  }
  return true;
}

GaussMarkovFactor::GaussMarkovFactor(double dt_s, double tau_s, double sigma,
                                     const Eigen::Matrix2d& shape_en)
    : phi_(std::exp(-dt_s / tau_s)) {
  // A floor on the driving noise keeps the factor finite for coincident states (dt = 0).
  const double sigma_w = std::max(sigma * std::sqrt(1.0 - phi_ * phi_), 1e-6 * sigma);
  sqrt_info_w_ = gnssSqrtInformation(sigma_w, sigma_w, shape_en);
}

bool GaussMarkovFactor::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> b_i(parameters[0]), b_j(parameters[1]);
  Eigen::Map<Eigen::Vector3d>{residuals} = sqrt_info_w_ * (b_j - phi_ * b_i);
  using Jac3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Map<Jac3>{jacobians[0]} = -phi_ * sqrt_info_w_;
  }
  if (jacobians != nullptr && jacobians[1] != nullptr) {
    Eigen::Map<Jac3>{jacobians[1]} = sqrt_info_w_;
  }
  return true;
}

void ReceiverBiasChains::add(ceres::Problem& problem, int quality, std::int64_t t_ns,
                             double sigma_b, const Eigen::Matrix2d& shape_en, double* bias) {
  const auto last = last_.find(quality);
  if (last == last_.end()) {
    const Eigen::Matrix3d A = gnssSqrtInformation(sigma_b, sigma_b, shape_en);
    problem.AddResidualBlock(new ceres::NormalPrior(A, Eigen::Vector3d::Zero()), nullptr, bias);
  } else {
    const double dt = static_cast<double>(t_ns - last->second.t_ns) * 1e-9;
    problem.AddResidualBlock(new GaussMarkovFactor(dt, tau_s_, sigma_b, shape_en), nullptr,
                             last->second.bias, bias);
  }
  last_[quality] = {t_ns, bias};
}

TiltFactor::TiltFactor(const Eigen::Vector3d& g_b, double sigma_rad)
    : g_b_(g_b.normalized()), inv_sigma_(1.0 / sigma_rad) {}

bool TiltFactor::Evaluate(double const* const* parameters, double* residuals,
                          double** jacobians) const {
  const Eigen::Matrix3d R = poseQ(parameters[0]).normalized().toRotationMatrix();
  const Eigen::Vector3d v = R.transpose() * Eigen::Vector3d::UnitZ();
  Eigen::Map<Eigen::Vector3d>{residuals} = inv_sigma_ * (v - g_b_);
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    // (R Exp(dphi))^T e_z = Exp(-dphi) v ~ v - hat(dphi) v = v + hat(v) dphi.
    Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
    J.leftCols<3>() = inv_sigma_ * hat(v);
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>>{jacobians[0]} =
        J * poseMinusJacobian(parameters[0]);
  }
  return true;
}

}  // namespace gvio::fusion
