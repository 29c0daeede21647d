#include "io/rotation_check.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace gvio::io {

std::optional<Eigen::Matrix3d> calibrationRotation(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) return std::nullopt;
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(err <= 1e-3) || !(R.determinant() > 0.0)) return std::nullopt;
  if (err <= 1e-9) return R;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose());
}

}  // namespace gvio::io
