#include "odometry/vi_alignment.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "odometry/lie.hpp"
#include "odometry/measurements.hpp"

namespace gvio::odometry {
namespace {

constexpr int kGravityRefinements = 4;

// Orthonormal basis of the plane perpendicular to g (VINS-Mono's TangentBasis).
Eigen::Matrix<double, 3, 2> tangentBasis(const Eigen::Vector3d& g) {
  const Eigen::Vector3d a = g.normalized();
  Eigen::Vector3d tmp(0, 0, 1);
  if ((a - tmp).norm() < 1e-3 || (a + tmp).norm() < 1e-3) tmp = Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d b = (tmp - a * a.dot(tmp)).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B << b, a.cross(b);
  return B;
}

// Linear system over x = [v_0 .. v_{n-1}, extra...] for the preintegration equations
//   v_k dt + 0.5 g dt^2 - s (p_{k+1} - p_k) = -R_k dp_k + (l_{k+1} - l_k)   (l: lever_v)
//   v_{k+1} - v_k - g dt                    =  R_k dv_k
// where g = g0 + B w when refining (B: 3x2 basis, w unknown) or g unknown (3), s optional.
struct LinearLayout {
  int n = 0;
  bool refine = false;  // gravity as g0 + B w
  bool scale = false;
  [[nodiscard]] int gravityCols() const { return refine ? 2 : 3; }
  [[nodiscard]] int size() const { return 3 * n + gravityCols() + (scale ? 1 : 0); }
  [[nodiscard]] int gravityCol() const { return 3 * n; }
  [[nodiscard]] int scaleCol() const { return 3 * n + gravityCols(); }
};

struct LinearSolution {
  Eigen::VectorXd x;
  double scale_variance = 0.0;  // of x(scaleCol) when the scale is estimated
};

std::optional<LinearSolution> solveLinear(const std::vector<AlignmentFrame>& frames,
                                          const LinearLayout& L, const Eigen::Vector3d& g0,
                                          const Eigen::Matrix<double, 3, 2>& B) {
  const int dim = L.size();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(dim);
  double yty = 0.0;
  for (int k = 0; k + 1 < L.n; ++k) {
    const AlignmentFrame& a = frames[static_cast<std::size_t>(k)];
    const AlignmentFrame& b = frames[static_cast<std::size_t>(k) + 1];
    const ImuPreintegration& pre = *b.preintegration;
    const double dt = pre.deltaT();
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(6, dim);
    Eigen::Matrix<double, 6, 1> y;
    Eigen::Matrix3d G_p = 0.5 * dt * dt * Eigen::Matrix3d::Identity();
    Eigen::Matrix3d G_v = -dt * Eigen::Matrix3d::Identity();
    y.head<3>() = -a.R_v_b * pre.deltaP();
    y.tail<3>() = a.R_v_b * pre.deltaV();
    A.block<3, 3>(0, 3 * k) = dt * Eigen::Matrix3d::Identity();
    A.block<3, 3>(3, 3 * k) = -Eigen::Matrix3d::Identity();
    A.block<3, 3>(3, 3 * (k + 1)) = Eigen::Matrix3d::Identity();
    if (L.refine) {
      A.block<3, 2>(0, L.gravityCol()) = G_p * B;
      A.block<3, 2>(3, L.gravityCol()) = G_v * B;
      y.head<3>() -= G_p * g0;
      y.tail<3>() -= G_v * g0;
    } else {
      A.block<3, 3>(0, L.gravityCol()) = G_p;
      A.block<3, 3>(3, L.gravityCol()) = G_v;
    }
    const Eigen::Vector3d dp_visual = b.p_v_b - a.p_v_b;
    y.head<3>() += b.lever_v - a.lever_v;  // metric: moves with the rotation, not the scale
    if (L.scale) {
      A.block<3, 1>(0, L.scaleCol()) = -dp_visual;
    } else {
      y.head<3>() += dp_visual;
    }
    H += A.transpose() * A;
    rhs += A.transpose() * y;
    yty += y.squaredNorm();
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  // A rank-deficient system (no motion information at all) shows as a tiny pivot.
  if (ldlt.vectorD().cwiseAbs().minCoeff() < 1e-10 * std::max(1.0, H.diagonal().maxCoeff())) {
    return std::nullopt;
  }
  LinearSolution out;
  out.x = ldlt.solve(rhs);
  if (!out.x.allFinite()) return std::nullopt;
  if (L.scale) {
    // Covariance = H^-1 * residual variance (unit weights; the residual sets the noise level).
    const int rows = 6 * (L.n - 1);
    const double ssr = std::max(0.0, yty - 2.0 * out.x.dot(rhs) + out.x.dot(H * out.x));
    const double variance = ssr / std::max(1, rows - dim);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(dim);
    e(L.scaleCol()) = 1.0;
    out.scale_variance = ldlt.solve(e)(L.scaleCol()) * variance;
  }
  return out;
}

}  // namespace

Eigen::Vector3d solveGyroBias(const std::vector<AlignmentFrame>& frames) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < frames.size(); ++k) {
    const ImuPreintegration& pre = *frames[k].preintegration;
    // Log(dR(bg)^T R_ij) ~= Log(dR^T R_ij) - dR_dbg dbg (first order in the bias change).
    const Eigen::Matrix3d R_ij = frames[k - 1].R_v_b.transpose() * frames[k].R_v_b;
    const Eigen::Vector3d e = logSo3(pre.deltaR().transpose() * R_ij);
    const Eigen::Matrix3d& J = pre.dR_dbg();
    H += J.transpose() * J;
    b += J.transpose() * e;
  }
  const Eigen::Vector3d delta = H.ldlt().solve(b);
  const ImuBias& lin =
      frames.size() > 1 ? frames[1].preintegration->linearizationBias() : ImuBias{};
  return lin.gyr + delta;
}

Eigen::Matrix3d gravityAlignment(const Eigen::Vector3d& g_v) {
  return Eigen::Quaterniond::FromTwoVectors(g_v.normalized(), Eigen::Vector3d(0, 0, -1))
      .toRotationMatrix();
}

std::optional<AlignmentResult> alignVisualInertial(std::vector<AlignmentFrame>& frames,
                                                   bool estimate_scale, double gravity_tolerance,
                                                   double max_scale_rel_sigma) {
  if (frames.size() < 3) return std::nullopt;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    if (!frames[k].preintegration) return std::nullopt;
  }
  AlignmentResult result;
  result.gyr_bias = solveGyroBias(frames);
  for (std::size_t k = 1; k < frames.size(); ++k) {
    ImuBias bias = frames[k].preintegration->linearizationBias();
    bias.gyr = result.gyr_bias;
    frames[k].preintegration->reintegrate(bias);
  }

  LinearLayout L;
  L.n = static_cast<int>(frames.size());
  L.scale = estimate_scale;
  const Eigen::Matrix<double, 3, 2> unused = Eigen::Matrix<double, 3, 2>::Zero();
  auto sol = solveLinear(frames, L, Eigen::Vector3d::Zero(), unused);
  if (!sol) return std::nullopt;
  Eigen::Vector3d g = sol->x.segment<3>(L.gravityCol());
  result.gravity_norm_before_refinement = g.norm();
  if (std::abs(g.norm() / kGravity_mps2 - 1.0) > gravity_tolerance) return std::nullopt;
  if (estimate_scale && !(sol->x(L.scaleCol()) > 0.0)) return std::nullopt;

  // Refine on the sphere |g| = 9.81: g = g0 + B w, re-normalised after each solve.
  L.refine = true;
  for (int it = 0; it < kGravityRefinements; ++it) {
    const Eigen::Vector3d g0 = g.normalized() * kGravity_mps2;
    const Eigen::Matrix<double, 3, 2> B = tangentBasis(g0);
    sol = solveLinear(frames, L, g0, B);
    if (!sol) return std::nullopt;
    g = (g0 + B * sol->x.segment<2>(L.gravityCol())).normalized() * kGravity_mps2;
  }
  result.g_v = g;
  result.scale = estimate_scale ? sol->x(L.scaleCol()) : 1.0;
  if (!(result.scale > 0.0)) return std::nullopt;
  if (estimate_scale) {
    result.scale_rel_sigma = std::sqrt(std::max(0.0, sol->scale_variance)) / result.scale;
    if (!(result.scale_rel_sigma <= max_scale_rel_sigma)) return std::nullopt;
  }
  result.v_v.resize(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    result.v_v[k] = sol->x.segment<3>(3 * static_cast<int>(k));
  }
  result.R_w_v = gravityAlignment(g);
  return result;
}

}  // namespace gvio::odometry
