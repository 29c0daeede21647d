#pragma once
// The linear algebra of marginalisation (odometry/marginalization.hpp): eigenpairs that count,
// and the Schur complement of a PSD system with pseudo-inverses, eliminated in two stages.
//
// The leaving blocks of a sliding window are mostly landmarks' inverse depths, and no residual
// names two of them: their part of H_mm is block diagonal. Eliminating those blocks one by one
// first (each a tiny pseudo-inverse) and then the few that are left (the oldest pose and its
// speed/bias) with one dense eigen-decomposition costs O(n^2 L) instead of the O((L + 15)^3) of
// decomposing all of H_mm. For PSD H the range of H_rm lies in that of H_mm, so the Schur
// complement does not depend on which generalised inverse is used and the two stages give the
// same H* as one (the quotient formula of Crabtree and Haynsworth, 1969), up to round-off and to
// directions dropped as numerically zero.
#include <Eigen/Core>
#include <vector>

namespace gvio::odometry {

struct MarginalizationOptions;

// Eigenpairs of the symmetric PSD matrix A whose eigenvalues exceed max(absolute, relative *
// max(scale_floor, largest eigenvalue)) of the options. Throws std::runtime_error when the
// decomposition fails.
struct Spectrum {
  Eigen::MatrixXd V;  // columns: eigenvectors kept
  Eigen::VectorXd s;  // their eigenvalues, > 0
};
[[nodiscard]] Spectrum significantSpectrum(const Eigen::MatrixXd& A, double scale_floor,
                                           const MarginalizationOptions& options);

// A leaving block's tangent columns [offset, offset + size) within the first m columns of H.
// `isolated`: no residual names it together with another isolated block (H_mm restricted to the
// isolated blocks is block diagonal).
struct LeavingBlock {
  int offset = 0;
  int size = 0;
  bool isolated = false;
};

// H* = H_rr - H_rm H_mm^+ H_mr and g* = g_r - H_rm H_mm^+ g_m for H (n x n, PSD) and g whose
// first m columns are the leaving blocks (which `leaving` lists, covering [0, m)).
struct SchurComplement {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
};
[[nodiscard]] SchurComplement schurComplement(const Eigen::MatrixXd& H, const Eigen::VectorXd& g,
                                              int m, const std::vector<LeavingBlock>& leaving,
                                              const MarginalizationOptions& options);

}  // namespace gvio::odometry
