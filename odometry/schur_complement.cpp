#include "odometry/schur_complement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>

#include "odometry/marginalization.hpp"

namespace gvio::odometry {
namespace {

double eigenvalueThreshold(double largest, double scale_floor,
                           const MarginalizationOptions& options) {
  const double scale = std::max(scale_floor, largest);
  return std::max(options.eigenvalue_absolute_threshold,
                  options.eigenvalue_relative_threshold * scale);
}

// The significant spectrum of a 1 x 1 block without an eigen-solver (most leaving blocks are
// inverse depths).
Spectrum scalarSpectrum(double value, double scale_floor, const MarginalizationOptions& options) {
  Spectrum out;
  if (value > eigenvalueThreshold(value, scale_floor, options) && value > 0.0) {
    out.V = Eigen::MatrixXd::Ones(1, 1);
    out.s = Eigen::VectorXd::Constant(1, value);
  }
  return out;
}

}  // namespace

Spectrum significantSpectrum(const Eigen::MatrixXd& A, double scale_floor,
                             const MarginalizationOptions& options) {
  Spectrum out;
  if (A.rows() == 0) return out;
  const Eigen::MatrixXd sym = 0.5 * (A + A.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(sym);
  if (solver.info() != Eigen::Success) {
    throw std::runtime_error("marginalization: eigen-decomposition failed");
  }
  const Eigen::VectorXd& values = solver.eigenvalues();  // ascending
  const double threshold = eigenvalueThreshold(values(values.size() - 1), scale_floor, options);
  Eigen::Index first = 0;
  while (first < values.size() && !(values(first) > threshold && values(first) > 0.0)) ++first;
  const Eigen::Index kept = values.size() - first;
  out.V = solver.eigenvectors().rightCols(kept);
  out.s = values.tail(kept);
  return out;
}

SchurComplement schurComplement(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, int m,
                                const std::vector<LeavingBlock>& leaving,
                                const MarginalizationOptions& options) {
  const int n = static_cast<int>(H.rows());
  const int nr = n - m;
  // Thresholds are relative to the size of H_mm (its largest diagonal entry) in both stages.
  const double scale = m > 0 ? std::max(H.topLeftCorner(m, m).diagonal().maxCoeff(), 0.0) : 0.0;

  // Stage 1: isolated blocks, H_mm^+ block by block. W = H_{o,b} V_b S_b^-1/2 for every other
  // column o, so that H_oo -= W W^T stays symmetric by construction (as in stage 2).
  std::vector<int> rest;  // the other columns: non-isolated leaving blocks, then the kept ones
  std::vector<std::pair<const LeavingBlock*, Spectrum>> spectra;
  int rank = 0;
  for (const LeavingBlock& b : leaving) {
    if (!b.isolated) {
      for (int c = 0; c < b.size; ++c) rest.push_back(b.offset + c);
      continue;
    }
    Spectrum s = b.size == 1 ? scalarSpectrum(H(b.offset, b.offset), scale, options)
                             : significantSpectrum(H.block(b.offset, b.offset, b.size, b.size),
                                                   scale, options);
    rank += static_cast<int>(s.s.size());
    if (s.s.size() > 0) spectra.emplace_back(&b, std::move(s));
  }
  const int m2 = static_cast<int>(rest.size());
  for (int c = m; c < n; ++c) rest.push_back(c);

  Eigen::MatrixXd H_rest = H(rest, rest);
  Eigen::VectorXd g_rest = g(rest);
  if (rank > 0) {
    Eigen::MatrixXd W(static_cast<Eigen::Index>(rest.size()), rank);
    Eigen::VectorXd w_g(rank);
    int col = 0;
    for (const auto& [b, s] : spectra) {
      const Eigen::Index k = s.s.size();
      const Eigen::VectorXd inv_sqrt = s.s.cwiseSqrt().cwiseInverse();
      W.middleCols(col, k) = H(rest, Eigen::seqN(b->offset, b->size)) * s.V * inv_sqrt.asDiagonal();
      w_g.segment(col, k) = inv_sqrt.cwiseProduct(s.V.transpose() * g.segment(b->offset, b->size));
      col += static_cast<int>(k);
    }
    H_rest.noalias() -= W * W.transpose();
    g_rest.noalias() -= W * w_g;
  }

  // Stage 2: what is left of H_mm, dense (VINS-Mono's pseudo-inverse H_mm^+ = V S^-1 V^T).
  SchurComplement out{H_rest.bottomRightCorner(nr, nr), g_rest.tail(nr)};
  if (m2 > 0) {
    const Spectrum mm = significantSpectrum(H_rest.topLeftCorner(m2, m2), scale, options);
    const Eigen::VectorXd inv_sqrt = mm.s.cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd W = H_rest.bottomLeftCorner(nr, m2) * mm.V * inv_sqrt.asDiagonal();
    out.H.noalias() -= W * W.transpose();
    out.g.noalias() -= W * inv_sqrt.cwiseProduct(mm.V.transpose() * g_rest.head(m2));
  }
  return out;
}

}  // namespace gvio::odometry
