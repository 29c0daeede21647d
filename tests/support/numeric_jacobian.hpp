#pragma once
// Central-difference Jacobians for checking analytic ones: column c is
// (f(x + h e_c) - f(x - h e_c)) / (2 h), where f takes the perturbation itself (so a test can
// apply it on a manifold, e.g. R Exp(dphi)). Truncation error O(h^2), round-off O(eps |f| / h).
#include <Eigen/Core>

namespace gvio::test {

// f: (const Eigen::Matrix<double, Cols, 1>& delta) -> Eigen::Matrix<double, Rows, 1>.
template <int Rows, int Cols, typename Fn>
Eigen::Matrix<double, Rows, Cols> numericJacobian(Fn&& f, double h = 1e-6) {
  Eigen::Matrix<double, Rows, Cols> J;
  for (int c = 0; c < Cols; ++c) {
    Eigen::Matrix<double, Cols, 1> delta = Eigen::Matrix<double, Cols, 1>::Zero();
    delta(c) = h;
    const Eigen::Matrix<double, Rows, 1> plus = f(delta);
    delta(c) = -h;
    const Eigen::Matrix<double, Rows, 1> minus = f(delta);
    J.col(c) = (plus - minus) / (2.0 * h);
  }
  return J;
}

}  // namespace gvio::test
