#include "odometry/imu_preintegration.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::odometry {
namespace {

constexpr double kSecondsPerNs = 1e-9;

void requireFiniteBias(const ImuBias& bias) {
  if (!bias.acc.allFinite() || !bias.gyr.allFinite()) {
    throw InvalidInput("imu preintegration: the linearisation bias must be finite");
  }
}

}  // namespace

ImuPreintegration::ImuPreintegration(const ImuBias& linearization_bias, const ImuNoise& noise)
    : linearization_bias_(linearization_bias), noise_(noise) {
  noise_.validate();
  requireFiniteBias(linearization_bias_);
}

void ImuPreintegration::integrate(const ImuSample& a, const ImuSample& b) {
  if (b.t_ns <= a.t_ns) {
    throw InvalidInput("imu preintegration: sample stamps must increase (got " +
                       std::to_string(a.t_ns) + " ns then " + std::to_string(b.t_ns) + " ns)");
  }
  const double dt_s = static_cast<double>(b.t_ns - a.t_ns) * kSecondsPerNs;
  integrate(dt_s, 0.5 * (a.acc_b_mps2 + b.acc_b_mps2), 0.5 * (a.gyr_b_radps + b.gyr_b_radps));
}

void ImuPreintegration::integrate(double dt_s, const Eigen::Vector3d& acc_b,
                                  const Eigen::Vector3d& gyr_b) {
  if (!std::isfinite(dt_s) || dt_s <= 0.0) {
    throw InvalidInput(
        "imu preintegration: the interval must be a positive number of seconds (got " +
        std::to_string(dt_s) + ")");
  }
  if (!acc_b.allFinite() || !gyr_b.allFinite()) {
    throw InvalidInput("imu preintegration: IMU measurements must be finite");
  }
  intervals_.push_back({dt_s, acc_b, gyr_b});
  propagate(intervals_.back());
}

void ImuPreintegration::reset() {
  delta_t_ = 0.0;
  delta_R_.setIdentity();
  delta_v_.setZero();
  delta_p_.setZero();
  covariance_.setZero();
  dR_dbg_.setZero();
  dv_dba_.setZero();
  dv_dbg_.setZero();
  dp_dba_.setZero();
  dp_dbg_.setZero();
}

void ImuPreintegration::reintegrate(const ImuBias& new_linearization_bias) {
  requireFiniteBias(new_linearization_bias);
  linearization_bias_ = new_linearization_bias;
  reset();
  for (const Interval& interval : intervals_) propagate(interval);
}

// One step k -> k+1 of eq. 35 with bias-corrected measurements held constant over dt:
//   dR_k+1 = dR_k Exp((gyr - b_g) dt)
//   dv_k+1 = dv_k + dR_k (acc - b_a) dt
//   dp_k+1 = dp_k + dv_k dt + 0.5 dR_k (acc - b_a) dt^2
// Covariance and bias Jacobians use dR_k, so they are propagated before the deltas.
void ImuPreintegration::propagate(const Interval& interval) {
  const double dt = interval.dt_s;
  const Eigen::Vector3d acc = interval.acc_b - linearization_bias_.acc;
  const Eigen::Vector3d phi_step = (interval.gyr_b - linearization_bias_.gyr) * dt;
  const Eigen::Matrix3d dR_step = expSo3(phi_step);
  const Eigen::Matrix3d acc_hat = hat(acc);

  propagateCovariance(dR_step, acc_hat, phi_step, dt);
  propagateBiasJacobians(dR_step, acc_hat, phi_step, dt);

  const Eigen::Vector3d acc_rotated = delta_R_ * acc;
  delta_p_ += delta_v_ * dt + 0.5 * acc_rotated * dt * dt;
  delta_v_ += acc_rotated * dt;
  delta_R_ = normalizeRotation(delta_R_ * dR_step);
  delta_t_ += dt;
}

// Eq. 62-63: eta_k+1 = A eta_k + B eta_d with eta = (dphi, dv, dp) and the discrete gyro and
// accelerometer noise eta_d ~ N(0, diag(n_g^2 / dt, n_a^2 / dt)) (continuous density n):
//   A = [dR_step^T                     0     0]    B = [Jr dt   0              ]
//       [-dR_k hat(acc) dt             I     0]        [0       dR_k dt        ]
//       [-0.5 dR_k hat(acc) dt^2       I dt  I]        [0       0.5 dR_k dt^2  ]
void ImuPreintegration::propagateCovariance(const Eigen::Matrix3d& dR_step,
                                            const Eigen::Matrix3d& acc_hat,
                                            const Eigen::Vector3d& phi_step, double dt) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Matrix9d A = Matrix9d::Identity();
  A.block<3, 3>(kRowR, kRowR) = dR_step.transpose();
  A.block<3, 3>(kRowV, kRowR) = -delta_R_ * acc_hat * dt;
  A.block<3, 3>(kRowP, kRowR) = -0.5 * delta_R_ * acc_hat * dt * dt;
  A.block<3, 3>(kRowP, kRowV) = I * dt;

  Eigen::Matrix<double, 9, 6> B = Eigen::Matrix<double, 9, 6>::Zero();
  B.block<3, 3>(kRowR, 0) = rightJacobianSo3(phi_step) * dt;
  B.block<3, 3>(kRowV, 3) = delta_R_ * dt;
  B.block<3, 3>(kRowP, 3) = 0.5 * delta_R_ * dt * dt;

  Eigen::Matrix<double, 6, 1> q;
  const double gyr_var = noise_.gyr_noise_density * noise_.gyr_noise_density / dt;
  const double acc_var = noise_.acc_noise_density * noise_.acc_noise_density / dt;
  q << gyr_var, gyr_var, gyr_var, acc_var, acc_var, acc_var;

  covariance_ = A * covariance_ * A.transpose() + B * q.asDiagonal() * B.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();
}

// Appendix B (the recursions behind eq. 69-70), with Jr^k = Jr((gyr - b_g) dt):
//   dR/dbg_k+1 = dR_step^T dR/dbg_k - Jr^k dt
//   dv/dba_k+1 = dv/dba_k - dR_k dt
//   dv/dbg_k+1 = dv/dbg_k - dR_k hat(acc) dR/dbg_k dt
//   dp/dba_k+1 = dp/dba_k + dv/dba_k dt - 0.5 dR_k dt^2
//   dp/dbg_k+1 = dp/dbg_k + dv/dbg_k dt - 0.5 dR_k hat(acc) dR/dbg_k dt^2
void ImuPreintegration::propagateBiasJacobians(const Eigen::Matrix3d& dR_step,
                                               const Eigen::Matrix3d& acc_hat,
                                               const Eigen::Vector3d& phi_step, double dt) {
  const Eigen::Matrix3d acc_term = delta_R_ * acc_hat * dR_dbg_;
  dp_dba_ += dv_dba_ * dt - 0.5 * delta_R_ * dt * dt;
  dp_dbg_ += dv_dbg_ * dt - 0.5 * acc_term * dt * dt;
  dv_dba_ -= delta_R_ * dt;
  dv_dbg_ -= acc_term * dt;
  dR_dbg_ = (dR_step.transpose() * dR_dbg_ - rightJacobianSo3(phi_step) * dt).eval();
}

// Forster eq. 48: the bias random walk integrated over deltaT has covariance n_b^2 deltaT.
Eigen::Matrix<double, 6, 6> ImuPreintegration::biasRandomWalkCovariance() const {
  Eigen::Matrix<double, 6, 1> d;
  const double acc_var = noise_.acc_random_walk * noise_.acc_random_walk * delta_t_;
  const double gyr_var = noise_.gyr_random_walk * noise_.gyr_random_walk * delta_t_;
  d << acc_var, acc_var, acc_var, gyr_var, gyr_var, gyr_var;
  return d.asDiagonal();
}

// Eq. 44: dR(b) = dR Exp(dR/dbg dbg), dv(b) = dv + dv/dba dba + dv/dbg dbg, dp(b) likewise, with
// db = b - linearisation bias.
Eigen::Matrix3d ImuPreintegration::correctedDeltaR(const ImuBias& b) const {
  return delta_R_ * expSo3(dR_dbg_ * (b.gyr - linearization_bias_.gyr));
}

Eigen::Vector3d ImuPreintegration::correctedDeltaV(const ImuBias& b) const {
  return delta_v_ + dv_dba_ * (b.acc - linearization_bias_.acc) +
         dv_dbg_ * (b.gyr - linearization_bias_.gyr);
}

Eigen::Vector3d ImuPreintegration::correctedDeltaP(const ImuBias& b) const {
  return delta_p_ + dp_dba_ * (b.acc - linearization_bias_.acc) +
         dp_dbg_ * (b.gyr - linearization_bias_.gyr);
}

bool ImuPreintegration::needsReintegration(const ImuBias& b, double acc_threshold,
                                           double gyr_threshold) const {
  return (b.acc - linearization_bias_.acc).norm() > acc_threshold ||
         (b.gyr - linearization_bias_.gyr).norm() > gyr_threshold;
}

// Eq. 45 (the residual errors of the preintegrated measurements).
ImuPreintegration::Vector9d ImuPreintegration::residual(
    const Eigen::Matrix3d& R_i, const Eigen::Vector3d& p_i, const Eigen::Vector3d& v_i,
    const Eigen::Matrix3d& R_j, const Eigen::Vector3d& p_j, const Eigen::Vector3d& v_j,
    const ImuBias& bias_i, const Eigen::Vector3d& g_w) const {
  const double dt = delta_t_;
  Vector9d r;
  r.segment<3>(kRowR) = logSo3(correctedDeltaR(bias_i).transpose() * R_i.transpose() * R_j);
  r.segment<3>(kRowV) = R_i.transpose() * (v_j - v_i - g_w * dt) - correctedDeltaV(bias_i);
  r.segment<3>(kRowP) =
      R_i.transpose() * (p_j - p_i - v_i * dt - 0.5 * g_w * dt * dt) - correctedDeltaP(bias_i);
  return r;
}

// Appendix C (eq. 65ff.), with r_R the rotation residual and dbg = bias_i.gyr - linearisation:
//   d r_R / dphi_i = -Jr^-1(r_R) R_j^T R_i        d r_R / dphi_j = Jr^-1(r_R)
//   d r_R / dbg    = -Jr^-1(r_R) Exp(r_R)^T Jr(dR/dbg dbg) dR/dbg
//   d r_v / dphi_i = hat(R_i^T (v_j - v_i - g dt))
//   d r_v / dv_i = -R_i^T,  d r_v / dv_j = R_i^T,  d r_v / db = -dv/db
//   d r_p / dphi_i = hat(R_i^T (p_j - p_i - v_i dt - 0.5 g dt^2))
//   d r_p / dp_i = -I,  d r_p / dv_i = -R_i^T dt,  d r_p / dp_j = R_i^T R_j,  d r_p / db = -dp/db
// The remaining blocks are zero. The position perturbation p <- p + R dp is what makes
// d r_p / dp_i = -I and d r_p / dp_j = R_i^T R_j.
void ImuPreintegration::residualJacobians(const Eigen::Matrix3d& R_i, const Eigen::Vector3d& p_i,
                                          const Eigen::Vector3d& v_i, const Eigen::Matrix3d& R_j,
                                          const Eigen::Vector3d& p_j, const Eigen::Vector3d& v_j,
                                          const ImuBias& bias_i, const Eigen::Vector3d& g_w,
                                          Jacobian9x24& J) const {
  const double dt = delta_t_;
  const Eigen::Matrix3d Ri_T = R_i.transpose();
  const Eigen::Vector3d dbg_phi = dR_dbg_ * (bias_i.gyr - linearization_bias_.gyr);
  const Eigen::Vector3d r_R = logSo3(correctedDeltaR(bias_i).transpose() * Ri_T * R_j);
  const Eigen::Matrix3d Jr_inv = rightJacobianInverseSo3(r_R);
  J.setZero();

  J.block<3, 3>(kRowR, kColPhiI) = -Jr_inv * R_j.transpose() * R_i;
  J.block<3, 3>(kRowR, kColPhiJ) = Jr_inv;
  J.block<3, 3>(kRowR, kColBiasGyr) =
      -Jr_inv * expSo3(r_R).transpose() * rightJacobianSo3(dbg_phi) * dR_dbg_;

  J.block<3, 3>(kRowV, kColPhiI) = hat(Ri_T * (v_j - v_i - g_w * dt));
  J.block<3, 3>(kRowV, kColVI) = -Ri_T;
  J.block<3, 3>(kRowV, kColVJ) = Ri_T;
  J.block<3, 3>(kRowV, kColBiasAcc) = -dv_dba_;
  J.block<3, 3>(kRowV, kColBiasGyr) = -dv_dbg_;

  J.block<3, 3>(kRowP, kColPhiI) = hat(Ri_T * (p_j - p_i - v_i * dt - 0.5 * g_w * dt * dt));
  J.block<3, 3>(kRowP, kColPI) = -Eigen::Matrix3d::Identity();
  J.block<3, 3>(kRowP, kColVI) = -Ri_T * dt;
  J.block<3, 3>(kRowP, kColPJ) = Ri_T * R_j;
  J.block<3, 3>(kRowP, kColBiasAcc) = -dp_dba_;
  J.block<3, 3>(kRowP, kColBiasGyr) = -dp_dbg_;
}

}  // namespace gvio::odometry
