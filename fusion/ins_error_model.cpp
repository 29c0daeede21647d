#include "fusion/ins_error_model.hpp"

#include <algorithm>
#include <cmath>

#include "odometry/lie.hpp"

namespace gvio::fusion {

using odometry::expSo3;
using odometry::hat;
using odometry::logSo3;
using odometry::normalizeRotation;
using odometry::rightJacobianSo3;

Eigen::Vector3d gravityEnu() {
  return {0.0, 0.0, -kGravity_mps2};
}

Eigen::Matrix3d rotationFromUpAndYaw(const Eigen::Vector3d& up_b, double yaw_rad) {
  const double pitch = std::asin(std::clamp(-up_b.x(), -1.0, 1.0));
  const double roll = std::atan2(up_b.y(), up_b.z());
  return odometry::rotationZyx({roll, pitch, yaw_rad});
}

InsState propagateNominal(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                          const Eigen::Vector3d& gyr_b_radps, double dt_s) {
  InsState y = x;
  const Eigen::Vector3d a_enu = x.R_enu_b * (acc_b_mps2 - x.ba_b_mps2) + gravityEnu();
  y.p_enu = x.p_enu + x.v_enu_mps * dt_s + 0.5 * a_enu * dt_s * dt_s;
  y.v_enu_mps = x.v_enu_mps + a_enu * dt_s;
  y.R_enu_b = normalizeRotation(x.R_enu_b * expSo3((gyr_b_radps - x.bg_b_radps) * dt_s));
  return y;
}

InsMatrix transitionMatrix(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                           const Eigen::Vector3d& gyr_b_radps, double dt_s) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d& R = x.R_enu_b;
  const Eigen::Vector3d phi = (gyr_b_radps - x.bg_b_radps) * dt_s;
  // d(acceleration in ENU) / d(dtheta) = -R [f - ba]x (Sola eq. 270).
  const Eigen::Matrix3d dA_dtheta = -R * hat(acc_b_mps2 - x.ba_b_mps2);
  InsMatrix Phi = InsMatrix::Identity();
  Phi.block<3, 3>(kInsP, kInsV) = dt_s * I;
  Phi.block<3, 3>(kInsP, kInsTheta) = 0.5 * dt_s * dt_s * dA_dtheta;
  Phi.block<3, 3>(kInsP, kInsBa) = -0.5 * dt_s * dt_s * R;
  Phi.block<3, 3>(kInsV, kInsTheta) = dt_s * dA_dtheta;
  Phi.block<3, 3>(kInsV, kInsBa) = -dt_s * R;
  // dtheta+ = Exp(phi)^T dtheta - Jr(phi) dt dbg (Sola eq. 272, exact rotation increment).
  Phi.block<3, 3>(kInsTheta, kInsTheta) = expSo3(phi).transpose();
  Phi.block<3, 3>(kInsTheta, kInsBg) = -dt_s * rightJacobianSo3(phi);
  return Phi;
}

InsMatrix processNoise(const ImuNoise& n, double time_offset_rw, double dt_s) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double qa = n.acc_noise_density * n.acc_noise_density;
  InsMatrix Q = InsMatrix::Zero();
  // Integrated white accelerometer noise: [[dt^3/3, dt^2/2], [dt^2/2, dt]] qa per axis (the
  // rotation R drops out of R qa I R^T).
  Q.block<3, 3>(kInsP, kInsP) = qa * dt_s * dt_s * dt_s / 3.0 * I;
  Q.block<3, 3>(kInsP, kInsV) = qa * dt_s * dt_s / 2.0 * I;
  Q.block<3, 3>(kInsV, kInsP) = Q.block<3, 3>(kInsP, kInsV);
  Q.block<3, 3>(kInsV, kInsV) = qa * dt_s * I;
  Q.block<3, 3>(kInsTheta, kInsTheta) = n.gyr_noise_density * n.gyr_noise_density * dt_s * I;
  Q.block<3, 3>(kInsBa, kInsBa) = n.acc_random_walk * n.acc_random_walk * dt_s * I;
  Q.block<3, 3>(kInsBg, kInsBg) = n.gyr_random_walk * n.gyr_random_walk * dt_s * I;
  Q(kInsTau, kInsTau) = time_offset_rw * time_offset_rw * dt_s;
  return Q;
}

InsState injectError(const InsState& x, const InsVector& dx) {
  InsState y = x;
  y.p_enu += dx.segment<3>(kInsP);
  y.v_enu_mps += dx.segment<3>(kInsV);
  y.R_enu_b = normalizeRotation(x.R_enu_b * expSo3(dx.segment<3>(kInsTheta)));
  y.ba_b_mps2 += dx.segment<3>(kInsBa);
  y.bg_b_radps += dx.segment<3>(kInsBg);
  y.time_offset_s += dx(kInsTau);
  return y;
}

InsVector errorBetween(const InsState& y, const InsState& x) {
  InsVector dx;
  dx.segment<3>(kInsP) = y.p_enu - x.p_enu;
  dx.segment<3>(kInsV) = y.v_enu_mps - x.v_enu_mps;
  dx.segment<3>(kInsTheta) = logSo3(x.R_enu_b.transpose() * y.R_enu_b);
  dx.segment<3>(kInsBa) = y.ba_b_mps2 - x.ba_b_mps2;
  dx.segment<3>(kInsBg) = y.bg_b_radps - x.bg_b_radps;
  dx(kInsTau) = y.time_offset_s - x.time_offset_s;
  return dx;
}

InsMatrix resetJacobian(const InsVector& dx) {
  InsMatrix G = InsMatrix::Identity();
  G.block<3, 3>(kInsTheta, kInsTheta) -= hat(0.5 * dx.segment<3>(kInsTheta));
  return G;
}

InsMeasurement<3> antennaPosition(const InsState& x, const Eigen::Vector3d& gyr_b_radps,
                                  const Eigen::Vector3d& lever_arm_b, double stamp_minus_filter_s) {
  const Eigen::Matrix3d& R = x.R_enu_b;
  const double dt = stamp_minus_filter_s + x.time_offset_s;
  const Eigen::Vector3d w_x_l = (gyr_b_radps - x.bg_b_radps).cross(lever_arm_b);
  const Eigen::Vector3d v_ant = x.v_enu_mps + R * w_x_l;  // antenna velocity (Groves eq. 2.165)
  InsMeasurement<3> m;
  m.h = x.p_enu + R * lever_arm_b + v_ant * dt;
  m.H.setZero();
  m.H.block<3, 3>(0, kInsP).setIdentity();
  m.H.block<3, 3>(0, kInsV) = dt * Eigen::Matrix3d::Identity();
  // R Exp(dth) l ~= R l - R [l]x dth; the same for the rotating-lever term [w]x l.
  m.H.block<3, 3>(0, kInsTheta) = -R * hat(lever_arm_b) - dt * R * hat(w_x_l);
  // [w - bg - dbg]x l = [w - bg]x l + [l]x dbg.
  m.H.block<3, 3>(0, kInsBg) = dt * R * hat(lever_arm_b);
  m.H.block<3, 1>(0, kInsTau) = v_ant;
  return m;
}

InsMeasurement<2> antennaVelocityEn(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                                    const Eigen::Vector3d& gyr_b_radps,
                                    const Eigen::Vector3d& lever_arm_b,
                                    double stamp_minus_filter_s) {
  const Eigen::Matrix3d& R = x.R_enu_b;
  const double dt = stamp_minus_filter_s + x.time_offset_s;
  const Eigen::Vector3d f_b = acc_b_mps2 - x.ba_b_mps2;
  const Eigen::Vector3d w_x_l = (gyr_b_radps - x.bg_b_radps).cross(lever_arm_b);
  const Eigen::Vector3d a_enu = R * f_b + gravityEnu();
  const Eigen::Vector3d v = x.v_enu_mps + R * w_x_l + a_enu * dt;
  Eigen::Matrix<double, 3, kInsDim> H3 = Eigen::Matrix<double, 3, kInsDim>::Zero();
  H3.block<3, 3>(0, kInsV).setIdentity();
  H3.block<3, 3>(0, kInsTheta) = -R * hat(w_x_l) - dt * R * hat(f_b);
  H3.block<3, 3>(0, kInsBa) = -dt * R;
  H3.block<3, 3>(0, kInsBg) = R * hat(lever_arm_b);
  H3.block<3, 1>(0, kInsTau) = a_enu;
  InsMeasurement<2> m;
  m.h = v.head<2>();
  m.H = H3.topRows<2>();
  return m;
}

InsMeasurement<2> vehicleLateralVerticalVelocity(const InsState& x, const Eigen::Matrix3d& R_v_b) {
  // R = R_hat Exp(dtheta): R^T v = (I - [dtheta]x) R_hat^T v = R_hat^T v + [R_hat^T v]x dtheta.
  const Eigen::Vector3d v_b = x.R_enu_b.transpose() * x.v_enu_mps;
  Eigen::Matrix<double, 3, kInsDim> H3 = Eigen::Matrix<double, 3, kInsDim>::Zero();
  H3.block<3, 3>(0, kInsV) = R_v_b * x.R_enu_b.transpose();
  H3.block<3, 3>(0, kInsTheta) = R_v_b * hat(v_b);
  InsMeasurement<2> m;
  m.h = (R_v_b * v_b).tail<2>();
  m.H = H3.bottomRows<2>();
  return m;
}

}  // namespace gvio::fusion
