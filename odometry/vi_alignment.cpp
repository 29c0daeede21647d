#include "odometry/vi_alignment.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
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
  double t_d_s = 0.0;  // the visual positions are the body's t_d before the stamps
  [[nodiscard]] int gravityCols() const { return refine ? 2 : 3; }
  [[nodiscard]] int size() const { return 3 * n + gravityCols() + (scale ? 1 : 0); }
  [[nodiscard]] int gravityCol() const { return 3 * n; }
  [[nodiscard]] int scaleCol() const { return 3 * n + gravityCols(); }
};

struct LinearSolution {
  Eigen::VectorXd x;
  double scale_variance = 0.0;  // of x(scaleCol) when the scale is estimated
  // Covariance of the gravity's tangent correction w (m/s^2)^2 when refining.
  Eigen::Matrix2d gravity_covariance = Eigen::Matrix2d::Zero();
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
    // p(stamp) = p_visual + v t_d: the visual displacement misses (v_{k+1} - v_k) t_d.
    A.block<3, 3>(0, 3 * k) = (dt + L.t_d_s) * Eigen::Matrix3d::Identity();
    A.block<3, 3>(0, 3 * (k + 1)) = -L.t_d_s * Eigen::Matrix3d::Identity();
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
  // Covariance = H^-1 * residual variance (unit weights; the residual sets the noise level).
  const int rows = 6 * (L.n - 1);
  const double ssr = std::max(0.0, yty - 2.0 * out.x.dot(rhs) + out.x.dot(H * out.x));
  const double variance = ssr / std::max(1, rows - dim);
  if (L.scale) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(dim);
    e(L.scaleCol()) = 1.0;
    out.scale_variance = ldlt.solve(e)(L.scaleCol()) * variance;
  }
  if (L.refine) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(dim, 2);
    E(L.gravityCol(), 0) = 1.0;
    E(L.gravityCol() + 1, 1) = 1.0;
    out.gravity_covariance = ldlt.solve(E).middleRows(L.gravityCol(), 2) * variance;
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

std::vector<Eigen::Vector3d> stampRates(const std::vector<AlignmentFrame>& frames) {
  const std::size_t n = frames.size();
  std::vector<Eigen::Vector3d> w(n, Eigen::Vector3d::Zero());
  if (n < 2) return w;
  // Mean rate over interval k (frames k-1 -> k), which is the rate at its midpoint to second
  // order, and that midpoint's time relative to frame 0's stamp.
  std::vector<Eigen::Vector3d> rate(n);
  std::vector<double> mid(n, 0.0);
  double t = 0.0;
  for (std::size_t k = 1; k < n; ++k) {
    const ImuPreintegration& pre = *frames[k].preintegration;
    const double dt = std::max(pre.deltaT(), 1e-9);
    rate[k] = logSo3(pre.deltaR()) / dt;
    mid[k] = t + 0.5 * dt;
    t += dt;
  }
  if (n == 2) return {rate[1], rate[1]};
  // Linear in time through the two nearest midpoints (extrapolated at the ends).
  auto at = [&](std::size_t a, double time) {
    const double w1 = (time - mid[a]) / (mid[a + 1] - mid[a]);
    return Eigen::Vector3d((1.0 - w1) * rate[a] + w1 * rate[a + 1]);
  };
  t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) t += frames[k].preintegration->deltaT();
    const std::size_t a = std::clamp<std::size_t>(k, 1, n - 2);
    w[k] = at(a, t);
  }
  return w;
}

GyroBiasTimeOffset solveGyroBiasAndTimeOffset(const std::vector<AlignmentFrame>& frames,
                                              const TimeOffsetPrior& prior) {
  GyroBiasTimeOffset out;
  out.t_d_s = prior.mean_s;
  out.t_d_sigma_s = prior.sigma_s;
  const std::vector<Eigen::Vector3d> w = stampRates(frames);
  using Mat4 = Eigen::Matrix4d;
  using Vec4 = Eigen::Vector4d;
  Mat4 H = Mat4::Zero();
  Vec4 g = Vec4::Zero();
  double ete = 0.0;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    const ImuPreintegration& pre = *frames[k].preintegration;
    const Eigen::Matrix3d R_ij = frames[k - 1].R_v_b.transpose() * frames[k].R_v_b;
    // The residual at the prior's t_d; the unknowns are the bias change and t_d - prior mean.
    Eigen::Matrix<double, 3, 4> A;
    A.leftCols<3>() = pre.dR_dbg();
    A.col(3) = pre.deltaR().transpose() * w[k - 1] - w[k];
    const Eigen::Vector3d e = logSo3(pre.deltaR().transpose() * R_ij) - A.col(3) * prior.mean_s;
    H += A.transpose() * A;
    g += A.transpose() * e;
    ete += e.squaredNorm();
  }
  const ImuBias& lin =
      frames.size() > 1 ? frames[1].preintegration->linearizationBias() : ImuBias{};
  const int rows = 3 * (static_cast<int>(frames.size()) - 1);
  const Eigen::LDLT<Mat4> ldlt(H + Mat4::Identity() * 1e-12 * std::max(1.0, H.trace()));
  const Vec4 x_ls = ldlt.solve(g);
  if (rows <= 4 || !x_ls.allFinite()) {
    out.gyr_bias = solveGyroBias(frames);
    return out;
  }
  // Residual variance of the unweighted fit; a floor keeps exact data from claiming infinite
  // precision (0.1 mrad per interval: well below any camera's rotation noise).
  const double ssr = std::max(0.0, ete - 2.0 * x_ls.dot(g) + x_ls.dot(H * x_ls));
  const double variance = std::max(ssr / (rows - 4), 1e-8);
  // MAP with the prior on t_d: (H / s^2 + P) x = g / s^2 (x(3) relative to the prior mean).
  Mat4 Hp = H / variance;
  Hp(3, 3) += 1.0 / (prior.sigma_s * prior.sigma_s);
  const Eigen::LDLT<Mat4> post(Hp);
  const Vec4 x = post.solve(g / variance);
  if (!x.allFinite()) {
    out.gyr_bias = solveGyroBias(frames);
    return out;
  }
  out.t_d_sigma_s = std::sqrt(std::max(0.0, post.solve(Vec4::UnitW())(3)));
  out.observed = out.t_d_sigma_s <= prior.max_sigma_s;
  if (!out.observed) {
    out.gyr_bias = solveGyroBias(frames);
    return out;
  }
  out.gyr_bias = lin.gyr + x.head<3>();
  out.t_d_s = prior.mean_s + x(3);
  return out;
}

Eigen::Matrix3d gravityAlignment(const Eigen::Vector3d& g_v) {
  return Eigen::Quaterniond::FromTwoVectors(g_v.normalized(), Eigen::Vector3d(0, 0, -1))
      .toRotationMatrix();
}

std::optional<AlignmentResult> alignVisualInertial(
    std::vector<AlignmentFrame>& frames, bool estimate_scale, double gravity_tolerance,
    double max_scale_rel_sigma, const std::optional<TimeOffsetPrior>& time_offset) {
  if (frames.size() < 3) return std::nullopt;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    if (!frames[k].preintegration) return std::nullopt;
  }
  AlignmentResult result;
  if (time_offset) {
    const GyroBiasTimeOffset solved = solveGyroBiasAndTimeOffset(frames, *time_offset);
    result.gyr_bias = solved.gyr_bias;
    result.t_d_s = solved.t_d_s;
    result.t_d_sigma_s = solved.t_d_sigma_s;
    result.t_d_observed = solved.observed;
  } else {
    result.gyr_bias = solveGyroBias(frames);
  }
  for (std::size_t k = 1; k < frames.size(); ++k) {
    ImuBias bias = frames[k].preintegration->linearizationBias();
    bias.gyr = result.gyr_bias;
    frames[k].preintegration->reintegrate(bias);
  }
  if (time_offset) result.w_b = stampRates(frames);  // at the solved bias

  LinearLayout L;
  L.n = static_cast<int>(frames.size());
  L.scale = estimate_scale;
  L.t_d_s = result.t_d_s;
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
  // The tangent correction w tilts g by |w| / |g| (rad); its largest 1-sigma is the tilt's.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(sol->gravity_covariance);
  result.tilt_sigma_rad = std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff())) / kGravity_mps2;
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
