#include "fusion/vio_enu_alignment.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace gvio::fusion {

std::optional<Eigen::Isometry3d> alignVioToEnu(const std::vector<Eigen::Vector3d>& p_w,
                                               const std::vector<Eigen::Vector3d>& p_enu,
                                               AlignmentDof dof, double min_extent_m,
                                               double min_cross_extent_m) {
  if (p_w.size() != p_enu.size() || p_w.size() < 3) return std::nullopt;
  const auto n = static_cast<double>(p_w.size());
  Eigen::Vector3d mean_w = Eigen::Vector3d::Zero(), mean_e = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < p_w.size(); ++k) {
    mean_w += p_w[k];
    mean_e += p_enu[k];
  }
  mean_w /= n;
  mean_e /= n;
  double extent = 0.0;
  for (const auto& p : p_w) extent = std::max(extent, (p - mean_w).head<2>().norm());
  if (extent < min_extent_m) return std::nullopt;

  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (dof == AlignmentDof::kRotationTranslation && crossExtent(p_w) < min_cross_extent_m) {
    dof = AlignmentDof::kYawTranslation;
  }
  if (dof == AlignmentDof::kYawTranslation) {
    // Minimising sum |Rz(yaw) a_k - b_k|^2 over centred points: yaw = atan2(sum a x b, sum a . b)
    // in the horizontal plane (the vertical components do not depend on yaw).
    double s = 0.0, c = 0.0;
    for (std::size_t k = 0; k < p_w.size(); ++k) {
      const Eigen::Vector3d a = p_w[k] - mean_w, b = p_enu[k] - mean_e;
      s += a.x() * b.y() - a.y() * b.x();
      c += a.x() * b.x() + a.y() * b.y();
    }
    T.linear() = Eigen::AngleAxisd(std::atan2(s, c), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else {
    Eigen::Matrix3Xd src(3, p_w.size()), dst(3, p_w.size());
    for (std::size_t k = 0; k < p_w.size(); ++k) {
      src.col(static_cast<Eigen::Index>(k)) = p_w[k];
      dst.col(static_cast<Eigen::Index>(k)) = p_enu[k];
    }
    const Eigen::Matrix4d M = Eigen::umeyama(src, dst, false);
    T.linear() = M.topLeftCorner<3, 3>();
  }
  T.translation() = mean_e - T.linear() * mean_w;
  return T;
}

double crossExtent(const std::vector<Eigen::Vector3d>& p) {
  if (p.size() < 2) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : p) mean += x;
  mean /= static_cast<double>(p.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& x : p) cov += (x - mean) * (x - mean).transpose();
  cov /= static_cast<double>(p.size());
  // Eigenvalues in increasing order: the middle one is the spread across the principal direction.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(eig.eigenvalues()(1), 0.0));
}

std::optional<Eigen::Isometry3d> interpolatePose(const Trajectory& traj, std::int64_t t_ns,
                                                 std::int64_t max_gap_ns) {
  if (traj.t_ns.empty() || t_ns < traj.t_ns.front() || t_ns > traj.t_ns.back()) {
    return std::nullopt;
  }
  const auto it = std::lower_bound(traj.t_ns.begin(), traj.t_ns.end(), t_ns);
  const auto j = static_cast<std::size_t>(it - traj.t_ns.begin());
  if (traj.t_ns[j] == t_ns) return traj.poses[j];
  const std::size_t i = j - 1;
  const std::int64_t gap = traj.t_ns[j] - traj.t_ns[i];
  if (gap > max_gap_ns) return std::nullopt;
  const double w = static_cast<double>(t_ns - traj.t_ns[i]) / static_cast<double>(gap);
  const Eigen::Quaterniond qa(traj.poses[i].rotation()), qb(traj.poses[j].rotation());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = qa.slerp(w, qb).toRotationMatrix();
  T.translation() = (1.0 - w) * traj.poses[i].translation() + w * traj.poses[j].translation();
  return T;
}

}  // namespace gvio::fusion
