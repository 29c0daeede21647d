#include "fusion/gnss_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace gvio::fusion {

Eigen::Matrix2d horizontalShape(const Eigen::Matrix2d& cov_en) {
  if (!cov_en.allFinite() ||
      std::abs(cov_en(0, 1) - cov_en(1, 0)) > 1e-9 * std::max(1.0, cov_en.cwiseAbs().maxCoeff())) {
    return Eigen::Matrix2d::Identity();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov_en);
  const Eigen::Vector2d lambda = eig.eigenvalues();  // ascending
  if (!(lambda(0) > 0.0)) return Eigen::Matrix2d::Identity();
  const double min_variance = kMinEllipseAxisRatio * kMinEllipseAxisRatio * lambda(1);
  const Eigen::Vector2d kept(std::max(lambda(0), min_variance), lambda(1));
  const Eigen::Matrix2d shape =
      eig.eigenvectors() * kept.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Matrix2d normalised = 2.0 * shape / shape.trace();
  return 0.5 * (normalised + normalised.transpose());
}

HorizontalError flooredHorizontal(const Eigen::Matrix2d& cov_en, double floor_m) {
  const double stated = 0.5 * cov_en.trace();
  const double added = std::max(floor_m * floor_m - std::max(stated, 0.0), 0.0);
  const Eigen::Matrix2d cov = cov_en + added * Eigen::Matrix2d::Identity();
  return {std::max(std::sqrt(std::max(stated, 0.0)), floor_m), horizontalShape(cov)};
}

Eigen::Matrix2d ellipseCovariance(double major_m, double minor_m, double orientation_deg) {
  const double theta = orientation_deg * std::numbers::pi / 180.0;
  const Eigen::Vector2d u(std::sin(theta), std::cos(theta));   // major axis (east, north)
  const Eigen::Vector2d v(std::cos(theta), -std::sin(theta));  // minor axis
  return major_m * major_m * u * u.transpose() + minor_m * minor_m * v * v.transpose();
}

Ellipse ellipseOf(const Eigen::Matrix2d& cov_en) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (cov_en + cov_en.transpose()));
  const Eigen::Vector2d u = eig.eigenvectors().col(1);  // the larger eigenvalue's
  double orientation = std::atan2(u.x(), u.y()) * 180.0 / std::numbers::pi;
  orientation = std::fmod(orientation + 360.0, 180.0);
  return {std::sqrt(std::max(eig.eigenvalues()(1), 0.0)),
          std::sqrt(std::max(eig.eigenvalues()(0), 0.0)), orientation};
}

Eigen::Matrix3d gnssCovariance(double sigma_h_m, double sigma_v_m,
                               const Eigen::Matrix2d& shape_en) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.topLeftCorner<2, 2>() = sigma_h_m * sigma_h_m * shape_en;
  cov(2, 2) = sigma_v_m * sigma_v_m;
  return cov;
}

Eigen::Matrix3d gnssSqrtInformation(double sigma_h_m, double sigma_v_m,
                                    const Eigen::Matrix2d& shape_en) {
  Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
  W(2, 2) = 1.0 / sigma_v_m;
  if (shape_en == Eigen::Matrix2d::Identity()) {  // a circle: exactly 1 / sigma_h per axis
    W(0, 0) = W(1, 1) = 1.0 / sigma_h_m;
    return W;
  }
  // information = cov^-1 = L L^T (Cholesky), so W = L^T gives W^T W = cov^-1.
  const Eigen::Matrix2d info_h = (sigma_h_m * sigma_h_m * shape_en).inverse();
  const Eigen::Matrix2d L = info_h.llt().matrixL();
  W.topLeftCorner<2, 2>() = L.transpose();
  return W;
}

}  // namespace gvio::fusion
