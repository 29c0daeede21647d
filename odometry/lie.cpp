#include "odometry/lie.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace gvio::odometry {
namespace {

// Below this angle the trigonometric coefficients use their Taylor series: the closed forms
// divide by powers of theta and lose digits to cancellation. With the terms kept below the
// truncation error is under theta^6 / 5040 < 2e-16.
constexpr double kTaylorAngle = 1e-2;

// t / sin t needs a series only where sin t underflows or is 0; the division is exact otherwise.
constexpr double kLogTaylorAngle = 1e-4;

// Within this distance of pi, Log takes the axis from the symmetric part of R: the skew part
// (sin(theta) times the axis) vanishes there and would amplify round-off by 1 / sin(theta).
constexpr double kNearPiAngle = 1e-2;

// (1 - cos t) / t^2 without cancellation: 1 - cos t = 2 sin^2(t / 2).
double oneMinusCosOverSq(double theta) {
  if (theta < kTaylorAngle) {
    const double t2 = theta * theta;
    return 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
  }
  const double s = std::sin(0.5 * theta);
  return 2.0 * s * s / (theta * theta);
}

// sin t / t.
double sinOverT(double theta) {
  if (theta < kTaylorAngle) {
    const double t2 = theta * theta;
    return 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
  }
  return std::sin(theta) / theta;
}

// (t - sin t) / t^3.
double tMinusSinOverCube(double theta) {
  if (theta < kTaylorAngle) {
    const double t2 = theta * theta;
    return 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  }
  return (theta - std::sin(theta)) / (theta * theta * theta);
}

// 1 / t^2 - (1 + cos t) / (2 t sin t) of eq. 9, written with (1 + cos t) / sin t = cot(t / 2) so
// that it stays finite at t = pi.
double inverseJacobianCoefficient(double theta) {
  if (theta < kTaylorAngle) {
    const double t2 = theta * theta;
    return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  }
  const double half = 0.5 * theta;
  return 1.0 / (theta * theta) - std::cos(half) / (2.0 * theta * std::sin(half));
}

// Axis of a rotation by about pi: (R + R^T) / 2 - cos(theta) I = (1 - cos(theta)) a a^T (from
// eq. 3 with hat(a)^2 = a a^T - I); its largest diagonal entry gives the best-conditioned column.
// The sign (irrelevant exactly at pi) follows the skew part sin(theta) a.
Eigen::Vector3d axisNearPi(const Eigen::Matrix3d& R, double cos_theta,
                           const Eigen::Vector3d& sin_axis) {
  const Eigen::Matrix3d S = 0.5 * (R + R.transpose()) - cos_theta * Eigen::Matrix3d::Identity();
  Eigen::Index i = 0;
  S.diagonal().maxCoeff(&i);
  Eigen::Vector3d axis = S.col(i).normalized();
  if (axis.dot(sin_axis) < 0.0) axis = -axis;
  return axis;
}

}  // namespace

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return W;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& W) {
  return 0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
}

// Eq. 3: Exp(phi) = I + sin(t) / t hat(phi) + (1 - cos t) / t^2 hat(phi)^2, t = |phi|.
Eigen::Matrix3d expSo3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = hat(phi);
  return Eigen::Matrix3d::Identity() + sinOverT(theta) * W + oneMinusCosOverSq(theta) * W * W;
}

// Eq. 5: Log(R) = t (R - R^T)^vee / (2 sin t), with t = atan2(|skew part|, (tr R - 1) / 2), which
// is accurate over [0, pi] where acos((tr R - 1) / 2) is not near 0 and pi.
Eigen::Vector3d logSo3(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d sin_axis = vee(R);  // sin(t) a
  const double sin_theta = sin_axis.norm();
  const double cos_theta = 0.5 * (R.trace() - 1.0);
  const double theta = std::atan2(sin_theta, cos_theta);
  if (theta > std::numbers::pi - kNearPiAngle) {
    return theta * axisNearPi(R, cos_theta, sin_axis);
  }
  if (theta < kLogTaylorAngle) {
    return (1.0 + theta * theta / 6.0) * sin_axis;  // t / sin t, error < 7 t^4 / 360 < 2e-18
  }
  return (theta / sin_theta) * sin_axis;
}

// Eq. 8: Jr(phi) = I - (1 - cos t) / t^2 hat(phi) + (t - sin t) / t^3 hat(phi)^2.
Eigen::Matrix3d rightJacobianSo3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = hat(phi);
  return Eigen::Matrix3d::Identity() - oneMinusCosOverSq(theta) * W +
         tMinusSinOverCube(theta) * W * W;
}

// Eq. 9: Jr^-1(phi) = I + hat(phi) / 2 + (1 / t^2 - (1 + cos t) / (2 t sin t)) hat(phi)^2.
Eigen::Matrix3d rightJacobianInverseSo3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = hat(phi);
  return Eigen::Matrix3d::Identity() + 0.5 * W + inverseJacobianCoefficient(theta) * W * W;
}

// Orthogonal Procrustes: M = U S V^T -> U diag(1, 1, det(U V^T)) V^T.
Eigen::Matrix3d normalizeRotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d d = Eigen::Vector3d::Ones();
  d.z() = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
}

Eigen::Matrix3d rotationZyx(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d eulerZyx(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
}

}  // namespace gvio::odometry
