#include "fusion/ins_mount.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

#include "odometry/lie.hpp"

namespace gvio::fusion {

void MountEstimator::add(const Eigen::Vector3d& v_b) {
  const double speed = v_b.norm();
  if (!std::isfinite(speed) || speed < config_.min_speed_mps) return;
  const Eigen::Vector3d u = v_b / speed;
  scatter_ += u * u.transpose();
  sum_ += u;
  ++samples_;
}

std::optional<MountEstimate> MountEstimator::estimate(const Eigen::Matrix3d& R_v_b_config) const {
  if (samples_ < config_.min_samples) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter_);
  if (eig.info() != Eigen::Success) return std::nullopt;
  const double concentration = eig.eigenvalues()(2) / static_cast<double>(samples_);
  if (!(concentration >= config_.min_concentration)) return std::nullopt;
  Eigen::Vector3d e = eig.eigenvectors().col(2);
  if (e.dot(sum_) < 0.0) e = -e;  // most epochs drive forward
  MountEstimate m;
  const Eigen::Vector3d forward = R_v_b_config * e;  // where the configured mount puts it
  m.R_v_b =
      Eigen::Quaterniond::FromTwoVectors(forward, Eigen::Vector3d::UnitX()).toRotationMatrix() *
      R_v_b_config;
  m.rpy_rad = odometry::eulerZyx(m.R_v_b);
  m.samples = samples_;
  m.concentration = concentration;
  return m;
}

}  // namespace gvio::fusion
