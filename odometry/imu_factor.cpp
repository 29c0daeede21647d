#include "odometry/imu_factor.hpp"

#include <Eigen/Cholesky>
#include <utility>

#include "odometry/pose_manifold.hpp"

namespace gvio::odometry {
namespace {

using Jac15x7 = Eigen::Matrix<double, kImuResidualSize, 7, Eigen::RowMajor>;
using Jac15x9 = Eigen::Matrix<double, kImuResidualSize, kSpeedBiasSize, Eigen::RowMajor>;

struct State {
  Eigen::Matrix3d R;
  Eigen::Vector3d p, v;
  ImuBias bias;
};

State stateOf(const double* pose, const double* speed_bias) {
  State s;
  s.R = poseQ(pose).normalized().toRotationMatrix();
  s.p = poseP(pose);
  s.v = Eigen::Map<const Eigen::Vector3d>(speed_bias);
  s.bias.acc = Eigen::Map<const Eigen::Vector3d>(speed_bias + 3);
  s.bias.gyr = Eigen::Map<const Eigen::Vector3d>(speed_bias + 6);
  return s;
}

}  // namespace

ImuFactor::ImuFactor(std::shared_ptr<const ImuPreintegration> preintegration,
                     const Eigen::Vector3d& g_w)
    : preintegration_(std::move(preintegration)), g_w_(g_w) {
  Matrix15d covariance = Matrix15d::Zero();
  covariance.topLeftCorner<9, 9>() = preintegration_->covariance();
  covariance.bottomRightCorner<6, 6>() = preintegration_->biasRandomWalkCovariance();
  // Information = L L^T of the inverse covariance; the whitening matrix is L^T, so that
  // |L^T r|^2 = r^T Sigma^-1 r.
  const Matrix15d information = covariance.inverse();
  const Eigen::LLT<Matrix15d> llt(0.5 * (information + information.transpose()));
  sqrt_information_ = llt.matrixL().transpose();
}

ImuFactor::Vector15d ImuFactor::rawResidual(double const* const* parameters) const {
  const State i = stateOf(parameters[0], parameters[1]);
  const State j = stateOf(parameters[2], parameters[3]);
  Vector15d r;
  r.head<9>() = preintegration_->residual(i.R, i.p, i.v, j.R, j.p, j.v, i.bias, g_w_);
  r.segment<3>(9) = j.bias.acc - i.bias.acc;
  r.segment<3>(12) = j.bias.gyr - i.bias.gyr;
  return r;
}

bool ImuFactor::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  Eigen::Map<Vector15d>{residuals} = sqrt_information_ * rawResidual(parameters);
  if (jacobians == nullptr) return true;

  const State i = stateOf(parameters[0], parameters[1]);
  const State j = stateOf(parameters[2], parameters[3]);
  ImuPreintegration::Jacobian9x24 J9;
  preintegration_->residualJacobians(i.R, i.p, i.v, j.R, j.p, j.v, i.bias, g_w_, J9);
  using C = ImuPreintegration;

  // Tangent-space Jacobians, then whitening and the pose blocks' MinusJacobian (pose_manifold.hpp).
  Eigen::Matrix<double, kImuResidualSize, 6> J_pose_i = Eigen::Matrix<double, 15, 6>::Zero();
  Eigen::Matrix<double, kImuResidualSize, 6> J_pose_j = Eigen::Matrix<double, 15, 6>::Zero();
  Eigen::Matrix<double, kImuResidualSize, 9> J_sb_i = Eigen::Matrix<double, 15, 9>::Zero();
  Eigen::Matrix<double, kImuResidualSize, 9> J_sb_j = Eigen::Matrix<double, 15, 9>::Zero();
  J_pose_i.topRows<9>() << J9.middleCols<3>(C::kColPhiI), J9.middleCols<3>(C::kColPI);
  J_pose_j.topRows<9>() << J9.middleCols<3>(C::kColPhiJ), J9.middleCols<3>(C::kColPJ);
  J_sb_i.topRows<9>() << J9.middleCols<3>(C::kColVI), J9.middleCols<3>(C::kColBiasAcc),
      J9.middleCols<3>(C::kColBiasGyr);
  J_sb_j.topLeftCorner<9, 3>() = J9.middleCols<3>(C::kColVJ);
  J_sb_i.bottomRightCorner<6, 6>() = -Eigen::Matrix<double, 6, 6>::Identity();
  J_sb_j.bottomRightCorner<6, 6>() = Eigen::Matrix<double, 6, 6>::Identity();

  if (jacobians[0] != nullptr) {
    Eigen::Map<Jac15x7>{jacobians[0]} =
        sqrt_information_ * J_pose_i * poseMinusJacobian(parameters[0]);
  }
  if (jacobians[1] != nullptr) Eigen::Map<Jac15x9>{jacobians[1]} = sqrt_information_ * J_sb_i;
  if (jacobians[2] != nullptr) {
    Eigen::Map<Jac15x7>{jacobians[2]} =
        sqrt_information_ * J_pose_j * poseMinusJacobian(parameters[2]);
  }
  if (jacobians[3] != nullptr) Eigen::Map<Jac15x9>{jacobians[3]} = sqrt_information_ * J_sb_j;
  return true;
}

}  // namespace gvio::odometry
