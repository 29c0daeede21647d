#pragma once
// Strapdown mechanisation and the 16-D error-state model of the GNSS/INS filter
// (fusion/gnss_ins.hpp) in local ENU, after J. Sola, "Quaternion kinematics for the error-state
// Kalman filter", 2017 (equation numbers below refer to it) and P. D. Groves, "Principles of GNSS,
// Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., ch. 14 (loosely coupled
// integration).
//
// Nominal state: p_enu, v_enu, R_enu_b (body -> ENU), accelerometer and gyro biases (body), and the
// GNSS receiver time offset (a fix stamped t is the antenna position at t + time_offset_s).
// Error state dx = (dp, dv, dtheta, dba, dbg, dtau): additive except the attitude, which is
// perturbed on the right, R = R_hat Exp(dtheta) (local angular error, Sola section 5.3.3), as the
// odometry library's preintegration does (odometry/lie.hpp).
#include <Eigen/Core>

#include "odometry/measurements.hpp"

namespace gvio::fusion {

inline constexpr int kInsDim = 16;
inline constexpr int kInsP = 0, kInsV = 3, kInsTheta = 6, kInsBa = 9, kInsBg = 12, kInsTau = 15;
using InsVector = Eigen::Matrix<double, kInsDim, 1>;
using InsMatrix = Eigen::Matrix<double, kInsDim, kInsDim>;

struct InsState {
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_enu_mps = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_enu_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d ba_b_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg_b_radps = Eigen::Vector3d::Zero();
  double time_offset_s = 0.0;
};

// Gravity in local ENU, g = (0, 0, -kGravity_mps2) as the odometry library uses it.
Eigen::Vector3d gravityEnu();

// Body -> ENU rotation from the body's up direction (unit, body frame) and the heading of the
// body x axis (rad, counter-clockwise from east): R = Rz(yaw) Ry(pitch) Rx(roll), with
// R^T e_up = (-sin pitch, cos pitch sin roll, cos pitch cos roll) (coarse levelling, Groves
// section 5.6.2).
Eigen::Matrix3d rotationFromUpAndYaw(const Eigen::Vector3d& up_b, double yaw_rad);

// One step of dt seconds with the IMU sample held constant over it (Sola eq. 260, with the exact
// rotation increment): R+ = R Exp((w - bg) dt), v+ = v + a dt, p+ = p + v dt + a dt^2 / 2 where
// a = R (f - ba) + g.
InsState propagateNominal(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                          const Eigen::Vector3d& gyr_b_radps, double dt_s);

// The exact linearisation of propagateNominal in the error state (Sola eq. 269-273 with the
// second-order position terms of this discrete scheme): dx+ = Phi dx.
InsMatrix transitionMatrix(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                           const Eigen::Vector3d& gyr_b_radps, double dt_s);

// Discrete process noise over dt from continuous white-noise densities (Sola eq. 262; Groves eq.
// 14.82 for the position/velocity coupling of integrated accelerometer noise); the time offset
// follows a random walk of density time_offset_rw (s/sqrt(s)).
InsMatrix processNoise(const ImuNoise& noise, double time_offset_rw, double dt_s);

// x_hat (+) dx (Sola eq. 283) and its inverse, y (-) x with y = x (+) dx.
InsState injectError(const InsState& x, const InsVector& dx);
InsVector errorBetween(const InsState& y, const InsState& x);

// Covariance reset after an injection (Sola eq. 287): G = I except -[dtheta/2]x on the attitude.
InsMatrix resetJacobian(const InsVector& dx);

template <int Rows>
struct InsMeasurement {
  Eigen::Matrix<double, Rows, 1> h;        // predicted measurement
  Eigen::Matrix<double, Rows, kInsDim> H;  // dh / d(error state)
};

// GNSS antenna position in ENU at the fix epoch t_stamp + time_offset, predicted from the state at
// filter time t_f (Groves eq. 14.120 with the lever arm; first order in the time difference
// dt = stamp_minus_filter_s + time_offset_s): h = p + R l + (v + R [w - bg]x l) dt.
InsMeasurement<3> antennaPosition(const InsState& x, const Eigen::Vector3d& gyr_b_radps,
                                  const Eigen::Vector3d& lever_arm_b, double stamp_minus_filter_s);

// Horizontal (east, north) antenna velocity at the same epoch (Groves eq. 14.123):
// h = [I2 0] (v + R [w - bg]x l + (R (f - ba) + g) dt).
InsMeasurement<2> antennaVelocityEn(const InsState& x, const Eigen::Vector3d& acc_b_mps2,
                                    const Eigen::Vector3d& gyr_b_radps,
                                    const Eigen::Vector3d& lever_arm_b,
                                    double stamp_minus_filter_s);

// Non-holonomic constraint of a land vehicle (Groves section 14.3.3 "motion constraints"; Shin
// 2001): a car moves along its forward axis, so its lateral and vertical velocities are near
// zero. h = [e_y e_z]^T R_v_b R^T v, the velocity in the vehicle frame (forward-left-up; R_v_b:
// IMU body -> vehicle, the mounting rotation), measured as 0.
InsMeasurement<2> vehicleLateralVerticalVelocity(const InsState& x, const Eigen::Matrix3d& R_v_b);

}  // namespace gvio::fusion
