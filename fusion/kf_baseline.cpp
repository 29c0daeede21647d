#include "fusion/kf_baseline.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <string>

#include "odometry/error.hpp"

namespace gvio::fusion {

void KfConfig::validate() const {
  const auto require = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0)) {
      throw InvalidInput(std::string("config: fusion.kf.") + name + " must be > 0");
    }
  };
  require(q_position, "q_position");
  require(q_velocity, "q_velocity");
  require(initial_position_sigma_m, "initial_position_sigma_m");
  require(initial_velocity_sigma_mps, "initial_velocity_sigma_mps");
}

KfBaseline::KfBaseline(const KfConfig& config) : config_(config) {
  config_.validate();
  P_.setZero();
  P_.topLeftCorner<3, 3>().diagonal().setConstant(std::pow(config.initial_position_sigma_m, 2));
  P_.bottomRightCorner<3, 3>().diagonal().setConstant(
      std::pow(config.initial_velocity_sigma_mps, 2));
}

KfBaseline::Matrix6d KfBaseline::processNoise(const KfConfig& c, double dt) {
  // With G = I: Qd = [[q_p dt + q_v dt^3 / 3, q_v dt^2 / 2], [q_v dt^2 / 2, q_v dt]] per axis.
  Matrix6d Q = Matrix6d::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Q.topLeftCorner<3, 3>() = (c.q_position * dt + c.q_velocity * dt * dt * dt / 3.0) * I;
  Q.topRightCorner<3, 3>() = (c.q_velocity * dt * dt / 2.0) * I;
  Q.bottomLeftCorner<3, 3>() = Q.topRightCorner<3, 3>();
  Q.bottomRightCorner<3, 3>() = (c.q_velocity * dt) * I;
  return Q;
}

void KfBaseline::predict(std::int64_t t_ns) {
  if (!started_) {
    started_ = true;
    t_ns_ = t_ns;
    return;
  }
  const double dt = static_cast<double>(t_ns - t_ns_) * 1e-9;
  if (!(dt > 0.0)) return;
  Matrix6d Phi = Matrix6d::Identity();
  Phi.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  x_ = Phi * x_;
  P_ = Phi * P_ * Phi.transpose() + processNoise(config_, dt);
  t_ns_ = t_ns;
}

double KfBaseline::update(const Vector6d& z, const Matrix6d& R) {
  // H = I6: S = P + R, K = P S^-1 (Joseph form keeps P symmetric positive definite).
  const Matrix6d S = P_ + R;
  const Eigen::LDLT<Matrix6d> ldlt(S);
  const Vector6d innovation = z - x_;
  const double nis = innovation.dot(ldlt.solve(innovation));
  const Matrix6d K = ldlt.solve(P_).transpose();  // P S^-1, S and P symmetric
  x_ += K * innovation;
  const Matrix6d I_K = Matrix6d::Identity() - K;
  P_ = I_K * P_ * I_K.transpose() + K * R * K.transpose();
  return nis;
}

}  // namespace gvio::fusion
