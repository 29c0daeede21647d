#include "odometry/schur_complement.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

#include "odometry/marginalization.hpp"

namespace gvio::odometry {
namespace {

// A window-shaped system: `depths` scalar leaving blocks (inverse depths), a 6-D leaving pose
// they all share residuals with, a 9-D leaving speed/bias, then `kept` columns. Residual rows
// follow that sparsity, so H_mm restricted to the depths is diagonal.
struct System {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  int m = 0;
  std::vector<LeavingBlock> leaving;
};

System windowSystem(int depths, int kept, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int pose = depths, speed_bias = depths + 6, m = depths + 15, n = m + kept;
  std::vector<Eigen::RowVectorXd> rows;
  const auto row = [&](const std::vector<std::pair<int, int>>& spans) {
    Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n);
    for (const auto& [first, size] : spans) {
      for (int c = first; c < first + size; ++c) r(c) = n01(rng);
    }
    rows.push_back(r);
  };
  for (int d = 0; d < depths; ++d) {
    for (int k = 0; k < 3; ++k) row({{d, 1}, {pose, 6}, {m + (d + k) % kept, 1}});
    row({{d, 1}});  // the stereo observation: the depth alone
  }
  for (int k = 0; k < 20; ++k) row({{pose, 6}, {speed_bias, 9}, {m, kept}});  // IMU and prior
  Eigen::MatrixXd J(static_cast<Eigen::Index>(rows.size()), n);
  for (std::size_t i = 0; i < rows.size(); ++i) J.row(static_cast<Eigen::Index>(i)) = rows[i];
  Eigen::VectorXd r(J.rows());
  for (Eigen::Index i = 0; i < r.size(); ++i) r(i) = n01(rng);
  System s{J.transpose() * J, J.transpose() * r, m, {}};
  for (int d = 0; d < depths; ++d) s.leaving.push_back({d, 1, true});
  s.leaving.push_back({pose, 6, false});
  s.leaving.push_back({speed_bias, 9, true});
  return s;
}

// One dense elimination with the Moore-Penrose inverse of all of H_mm.
SchurComplement denseReference(const System& s) {
  const Eigen::Index nr = s.H.rows() - s.m;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.H.topLeftCorner(s.m, s.m));
  const Eigen::VectorXd& values = eig.eigenvalues();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(values.size());
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (values(i) > 1e-10 * values.maxCoeff()) inv(i) = 1.0 / values(i);
  }
  const Eigen::MatrixXd pinv =
      eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::MatrixXd H_rm = s.H.bottomLeftCorner(nr, s.m);
  return {s.H.bottomRightCorner(nr, nr) - H_rm * pinv * H_rm.transpose(),
          s.g.tail(nr) - H_rm * pinv * s.g.head(s.m)};
}

void expectSame(const SchurComplement& a, const SchurComplement& b) {
  const double scale = b.H.cwiseAbs().maxCoeff();
  ASSERT_EQ(a.H.rows(), b.H.rows());
  EXPECT_LT((a.H - b.H).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_LT((a.g - b.g).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, b.g.cwiseAbs().maxCoeff()));
  EXPECT_TRUE(a.H.allFinite() && a.g.allFinite());
  EXPECT_LT((a.H - a.H.transpose()).cwiseAbs().maxCoeff(), 1e-12 * scale);
}

TEST(SchurComplement, TwoStagesMatchOneDenseElimination) {
  const System s = windowSystem(40, 24, 7);
  expectSame(schurComplement(s.H, s.g, s.m, s.leaving, MarginalizationOptions{}),
             denseReference(s));
}

TEST(SchurComplement, DirectionsWithoutInformationAreDropped) {
  // A depth no residual informs (its row and column zero) and a pose direction only the depths'
  // residuals see, which the dense reference also treats through the pseudo-inverse.
  System s = windowSystem(12, 10, 3);
  s.H.row(4).setZero();
  s.H.col(4).setZero();
  s.g(4) = 0.0;
  expectSame(schurComplement(s.H, s.g, s.m, s.leaving, MarginalizationOptions{}),
             denseReference(s));
}

TEST(SchurComplement, EveryLeavingBlockIsolatedOrNoneIsolated) {
  System all = windowSystem(10, 8, 11);
  // No two leaving blocks coupled (the depths' and the speed/bias' coupling to the pose removed):
  // every one may be eliminated on its own, and all together must give the same.
  for (const auto& [first, size] : {std::pair{0, 10}, std::pair{16, 9}}) {
    all.H.block(first, 10, size, 6).setZero();
    all.H.block(10, first, 6, size).setZero();
  }
  for (LeavingBlock& b : all.leaving) b.isolated = true;
  const SchurComplement reference = denseReference(all);
  expectSame(schurComplement(all.H, all.g, all.m, all.leaving, MarginalizationOptions{}),
             reference);
  for (LeavingBlock& b : all.leaving) b.isolated = false;
  expectSame(schurComplement(all.H, all.g, all.m, all.leaving, MarginalizationOptions{}),
             reference);
}

TEST(SchurComplement, NothingLeavingReturnsTheSystem) {
  const System s = windowSystem(5, 6, 1);
  const SchurComplement out = schurComplement(s.H, s.g, 0, {}, MarginalizationOptions{});
  EXPECT_EQ(out.H, s.H);
  EXPECT_EQ(out.g, s.g);
}

}  // namespace
}  // namespace gvio::odometry
