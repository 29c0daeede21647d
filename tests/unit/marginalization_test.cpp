#include "odometry/marginalization.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include "odometry/error.hpp"
#include "support/numeric_jacobian.hpp"

namespace gvio::odometry {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Quat = std::array<double, 4>;  // (w, x, y, z), ceres::QuaternionManifold's order

// r = sum_i A_i x_i - c: every linear residual below. Columns of A_i that are all zero are
// entries of x_i no residual sees.
class LinearCost final : public ceres::CostFunction {
 public:
  LinearCost(std::vector<Eigen::MatrixXd> A, Eigen::VectorXd c)
      : A_(std::move(A)), c_(std::move(c)) {
    set_num_residuals(static_cast<int>(c_.size()));
    for (const auto& a : A_) mutable_parameter_block_sizes()->push_back(static_cast<int>(a.cols()));
  }
  bool Evaluate(double const* const* p, double* r, double** jac) const override {
    Eigen::Map<Eigen::VectorXd> res(r, c_.size());
    res = -c_;
    for (std::size_t i = 0; i < A_.size(); ++i) {
      res += A_[i] * Eigen::Map<const Eigen::VectorXd>(p[i], A_[i].cols());
      if (jac == nullptr || jac[i] == nullptr) continue;
      Eigen::Map<RowMatrix> J(jac[i], A_[i].rows(), A_[i].cols());
      J = A_[i];
    }
    return true;
  }

 private:
  std::vector<Eigen::MatrixXd> A_;
  Eigen::VectorXd c_;
};

// r = A (x_j - x_i.head<2>() - z), x_i of size ni >= 2.
std::shared_ptr<ceres::CostFunction> relative(const Eigen::Matrix2d& A, const Eigen::Vector2d& z,
                                              int ni = 2) {
  Eigen::MatrixXd Ai = Eigen::MatrixXd::Zero(2, ni);
  Ai.leftCols(2) = -A;
  return std::make_shared<LinearCost>(std::vector<Eigen::MatrixXd>{Ai, A}, A * z);
}
// r = A (x - z).
std::shared_ptr<ceres::CostFunction> absolute(const Eigen::Matrix2d& A, const Eigen::Vector2d& z) {
  return std::make_shared<LinearCost>(std::vector<Eigen::MatrixXd>{A}, A * z);
}

// r = W * 2 vec(conj(meas) * conj(q_i) * q_j), or W * 2 vec(conj(meas) * q) on one block.
struct RotationResidual {
  Quat meas;
  Eigen::Vector3d weight;
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const T meas_conj[4] = {T(meas[0]), T(-meas[1]), T(-meas[2]), T(-meas[3])};
    T err[4];
    ceres::QuaternionProduct(meas_conj, q, err);
    for (int k = 0; k < 3; ++k) r[k] = T(2.0 * weight(k)) * err[k + 1];
    return true;
  }
  template <typename T>
  bool operator()(const T* qi, const T* qj, T* r) const {
    const T qi_conj[4] = {qi[0], -qi[1], -qi[2], -qi[3]};
    T rel[4];
    ceres::QuaternionProduct(qi_conj, qj, rel);
    return (*this)(rel, r);
  }
};

// Residual evaluation that fails, for the bad-use test.
class FailingCost final : public ceres::SizedCostFunction<1, 2> {
 public:
  bool Evaluate(double const* const*, double*, double**) const override { return false; }
};

Eigen::Matrix2d upperTriangular(double a, double b, double c) {
  Eigen::Matrix2d m;
  m << a, b, 0.0, c;
  return m;
}

Quat unitQuaternion(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  return {w / n, x / n, y / n, z / n};
}

std::shared_ptr<ceres::CostFunction> rotationCost(const Quat& meas, const Eigen::Vector3d& w) {
  return std::make_shared<ceres::AutoDiffCostFunction<RotationResidual, 3, 4, 4>>(
      new RotationResidual{meas, w});
}

// Gauss-Newton system H = J^T J, g = J^T r over the tangent spaces (and J where known).
struct Linearization {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  Eigen::MatrixXd J = {};
};

// Schur complement of the first m tangent dimensions with a plain inverse (full-rank H_mm).
Linearization schur(const Linearization& full, Eigen::Index m) {
  const Eigen::Index nr = full.H.rows() - m;
  const Eigen::MatrixXd Hmm_inv = full.H.topLeftCorner(m, m).inverse();
  const Eigen::MatrixXd Hrm = full.H.bottomLeftCorner(nr, m);
  return {full.H.bottomRightCorner(nr, nr) - Hrm * Hmm_inv * Hrm.transpose(),
          full.g.tail(nr) - Hrm * Hmm_inv * full.g.head(m)};
}

// A residual block, as the Marginalizer and a ceres::Problem both take it.
struct Term {
  std::shared_ptr<ceres::CostFunction> cost;
  std::vector<double*> blocks;
  std::shared_ptr<ceres::LossFunction> loss = nullptr;
};

// Builds the prior that removes `removed` from `terms`; `manifold` (if any) on every block.
std::shared_ptr<const MarginalizationPrior> marginalize(const std::vector<Term>& terms,
                                                        const std::vector<double*>& removed,
                                                        const ceres::Manifold* manifold = nullptr) {
  Marginalizer marginalizer;
  for (const Term& t : terms) {
    marginalizer.addResidualBlock(t.cost, t.loss, t.blocks);
    for (double* b : t.blocks) {
      if (manifold != nullptr) marginalizer.setManifold(b, manifold);
    }
  }
  for (double* b : removed) marginalizer.markForRemoval(b);
  return marginalizer.marginalize();
}

// A problem that borrows the terms' cost and loss functions.
std::unique_ptr<ceres::Problem> problemOf(const std::vector<Term>& terms,
                                          ceres::Manifold* manifold = nullptr) {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto problem = std::make_unique<ceres::Problem>(options);
  for (const Term& t : terms) {
    problem->AddResidualBlock(t.cost.get(), t.loss.get(), t.blocks);
    for (double* b : t.blocks) {
      if (manifold != nullptr) problem->SetManifold(b, manifold);
    }
  }
  return problem;
}

// H and g as Ceres itself evaluates them (manifolds and robust losses applied), blocks in order.
Linearization evaluateWithCeres(ceres::Problem& problem, const std::vector<double*>& blocks) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  double cost = 0.0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  EXPECT_TRUE(problem.Evaluate(options, &cost, &residuals, nullptr, &crs));
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> sparse(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  const Eigen::MatrixXd J = sparse;
  const Eigen::Map<const Eigen::VectorXd> r(residuals.data(),
                                            static_cast<Eigen::Index>(residuals.size()));
  return {J.transpose() * J, J.transpose() * r, J};
}

// The prior must hold H* = J^T J and g* = J^T r0.
void expectPrior(const std::shared_ptr<const MarginalizationPrior>& prior,
                 const Linearization& expected, double tolerance) {
  ASSERT_NE(prior, nullptr);
  EXPECT_LT((prior->information() - expected.H).cwiseAbs().maxCoeff(), tolerance);
  EXPECT_LT((prior->J.transpose() * prior->r0 - expected.g).cwiseAbs().maxCoeff(), tolerance);
}

void solveTightly(ceres::Problem& problem) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.function_tolerance = options.gradient_tolerance = options.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
}

double minEigenvalue(const Eigen::MatrixXd& A) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues()(0);
}

// Linear Gaussian chain x0 - x1 - x2 with a loop x0 - x2: marginalising x0 is exact.
TEST(Marginalization, LinearChainMatchesSchurComplementAndFullSolve) {
  const Eigen::Matrix2d A0 = upperTriangular(3.0, 0.4, 2.0), A01 = upperTriangular(2.0, -0.3, 1.5);
  const Eigen::Matrix2d A02 = upperTriangular(0.7, 0.2, 0.9), A12 = upperTriangular(1.8, 0.5, 2.2);
  const Eigen::Matrix2d A2 = upperTriangular(0.6, 0.0, 0.8);
  const Eigen::Vector2d z0(0.1, -0.2), z01(1.0, 0.3), z02(2.1, 0.5), z12(0.9, 0.4), z2(2.5, 1.0);
  const Eigen::Vector2d init0(0.3, 0.1), init1(0.5, 0.9), init2(1.7, -0.4);

  // The full system by hand, columns x0 | x1 | x2: rows r = A (x_j - x_i - z) (i < 0: A (x_j - z)).
  Eigen::VectorXd x_init(6);
  x_init << init0, init1, init2;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(10, 6);
  Eigen::VectorXd r(10);
  const auto put = [&](int row, int i, int j, const Eigen::Matrix2d& A, const Eigen::Vector2d& z) {
    if (i >= 0) J.block<2, 2>(row, 2 * i) = -A;
    J.block<2, 2>(row, 2 * j) = A;
    r.segment<2>(row) = J.middleRows<2>(row) * x_init - A * z;
  };
  put(0, -1, 0, A0, z0);
  put(2, 0, 1, A01, z01);
  put(4, 0, 2, A02, z02);
  put(6, 1, 2, A12, z12);
  put(8, -1, 2, A2, z2);
  const Linearization full = schur({J.transpose() * J, J.transpose() * r}, 2);
  // What the prior alone must hold: the Schur complement less the residuals that stay.
  const Eigen::MatrixXd J_stay = J.bottomRows(4).rightCols(4);
  const Linearization expected = {full.H - J_stay.transpose() * J_stay,
                                  full.g - J_stay.transpose() * r.tail(4)};

  using Block = std::array<double, 2>;
  Block x0{init0(0), init0(1)}, x1{init1(0), init1(1)}, x2{init2(0), init2(1)};
  Block f0 = x0, f1 = x1, f2 = x2, p1 = x1, p2 = x2;  // full and reduced problems' states
  const auto make = [&](Block& a, Block& b, Block& c) -> std::vector<Term> {
    return {{absolute(A0, z0), {a.data()}},
            {relative(A01, z01), {a.data(), b.data()}},
            {relative(A02, z02), {a.data(), c.data()}},
            {relative(A12, z12), {b.data(), c.data()}},
            {absolute(A2, z2), {c.data()}}};
  };
  std::vector<Term> terms = make(x0, x1, x2);
  const auto prior = marginalize({terms[0], terms[1], terms[2]}, {x0.data()});
  expectPrior(prior, expected, 1e-9);
  ASSERT_EQ(prior->blocks.size(), 2U);
  EXPECT_EQ(prior->blocks[0].original_address, x1.data());
  EXPECT_EQ(prior->blocks[1].original_address, x2.data());
  EXPECT_EQ(prior->J.rows(), 4);

  // Solving with the prior gives the full problem's x1, x2 (blocks at new addresses).
  solveTightly(*problemOf(make(f0, f1, f2)));
  terms = make(x0, p1, p2);
  terms.erase(terms.begin(), terms.begin() + 3);
  terms.push_back({std::make_shared<MarginalizationFactor>(prior), {p1.data(), p2.data()}});
  solveTightly(*problemOf(terms));
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_NEAR(p1[k], f1[k], 1e-8);
    EXPECT_NEAR(p2[k], f2[k], 1e-8);
  }
}

// A prior on a quaternion (Hamilton, QuaternionManifold), a Euclidean block and a pose
// (ProductManifold of EigenQuaternionManifold and R^3): ambient 4 + 3 + 7, tangent 3 + 3 + 6.
class MarginalizationFactorManifolds : public ::testing::Test {
 protected:
  using Pose = ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;
  static constexpr int kRows = 8, kCols = 12;
  using State = Eigen::Matrix<double, 14, 1>;  // the three blocks' ambient values, stacked
  using Delta = Eigen::Matrix<double, kCols, 1>;
  using Residual = Eigen::Matrix<double, kRows, 1>;

  MarginalizationFactorManifolds() {
    const Quat q = unitQuaternion(0.9, 0.2, -0.3, 0.1), pq = unitQuaternion(0.8, 0.1, -0.5, 0.2);
    // EigenQuaternionManifold stores (x, y, z, w).
    x0_ << q[0], q[1], q[2], q[3], 0.5, -1.0, 2.0, pq[1], pq[2], pq[3], pq[0], 1.0, 2.0, -3.0;
    const double* x = x0_.data();
    auto prior = std::make_shared<MarginalizationPrior>();
    prior->blocks = {{x, 4, 3, &quaternion_, nullptr, {x, x + 4}},
                     {x + 4, 3, 3, nullptr, nullptr, {x + 4, x + 7}},
                     {x + 7, 7, 6, &pose_, nullptr, {x + 7, x + 14}}};
    prior->J = Eigen::MatrixXd::Random(kRows, kCols) * 5.0;
    prior->r0 = Eigen::VectorXd::Random(kRows);
    prior_ = prior;
    factor_ = std::make_unique<MarginalizationFactor>(prior);
  }

  // Plus(x, delta) block by block.
  State plus(const State& x, const Delta& delta) const {
    State out = x;
    EXPECT_TRUE(quaternion_.Plus(x.data(), delta.data(), out.data()));
    out.segment<3>(4) += delta.segment<3>(3);
    EXPECT_TRUE(pose_.Plus(x.data() + 7, delta.data() + 6, out.data() + 7));
    return out;
  }
  Residual evaluate(const State& x) const {
    const std::array<const double*, 3> params = {x.data(), x.data() + 4, x.data() + 7};
    Residual r;
    EXPECT_TRUE(factor_->Evaluate(params.data(), r.data(), nullptr));
    return r;
  }

  ceres::QuaternionManifold quaternion_;
  Pose pose_;
  State x0_;
  std::shared_ptr<const MarginalizationPrior> prior_;
  std::unique_ptr<MarginalizationFactor> factor_;
};

TEST_F(MarginalizationFactorManifolds, ResidualIsLinearInTheTangentSpaceAroundX0) {
  EXPECT_EQ(factor_->num_residuals(), kRows);
  EXPECT_EQ(factor_->parameter_block_sizes(), (std::vector<std::int32_t>{4, 3, 7}));
  const Residual at_x0 = evaluate(x0_);
  for (int i = 0; i < kRows; ++i) EXPECT_EQ(at_x0(i), prior_->r0(i)) << i;

  Delta d;
  d << 0.01, -0.02, 0.015, 0.3, -0.1, 0.2, -0.012, 0.008, 0.02, 0.5, 0.1, -0.4;
  const Residual expected = prior_->r0 + prior_->J * d;
  EXPECT_LT((evaluate(plus(x0_, d)) - expected).norm(), 1e-8 * expected.norm());
}

TEST_F(MarginalizationFactorManifolds, CeresSeesTheFirstEstimateJacobian) {
  Delta far;  // well away from x0: the exact derivative of r there is not J any more
  far << 0.3, -0.2, 0.25, 1.0, 2.0, -1.0, -0.3, 0.2, 0.4, 0.5, -0.5, 1.0;
  State x = plus(x0_, far);
  // Ceres' chain rule J_ambient * PlusJacobian(x) gives J itself (blocks at new addresses).
  auto problem = problemOf({});
  problem->AddResidualBlock(factor_.get(), nullptr, x.data(), x.data() + 4, x.data() + 7);
  problem->SetManifold(x.data(), &quaternion_);
  problem->SetManifold(x.data() + 7, &pose_);
  const Linearization lin = evaluateWithCeres(*problem, {x.data(), x.data() + 4, x.data() + 7});
  ASSERT_EQ(lin.J.rows(), kRows);
  ASSERT_EQ(lin.J.cols(), kCols);
  EXPECT_LT((lin.J - prior_->J).cwiseAbs().maxCoeff(), 1e-12 * prior_->J.cwiseAbs().maxCoeff());

  // Near x0 the first-estimate Jacobian is the derivative of r(Plus(x, delta)) w.r.t. delta; far
  // from x0 it is not (the rotation blocks' Minus(x, x0) is nonlinear), by design.
  const auto numeric_at = [&](const State& at) {
    return test::numericJacobian<kRows, kCols>(
        [&](const Delta& delta) { return evaluate(plus(at, delta)); }, 1e-6);
  };
  const Delta tiny = far * 1e-8;
  const Eigen::MatrixXd near_error = numeric_at(plus(x0_, tiny)) - prior_->J;
  EXPECT_LT(near_error.cwiseAbs().maxCoeff(), 1e-6);
  const Eigen::MatrixXd far_error = numeric_at(x) - prior_->J;
  EXPECT_GT(far_error.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT(far_error.middleCols(3, 3).cwiseAbs().maxCoeff(), 1e-6);  // Euclidean stays exact
}

TEST(Marginalization, RankDeficientBlocksGiveFinitePsdPrior) {
  // (a) x_m has a third entry no residual sees: H_mm is singular. Compared with the same problem
  // without that entry, whose H_mm is invertible.
  const Eigen::Matrix2d A = upperTriangular(2.0, 0.5, 1.0), B = upperTriangular(1.0, 0.0, 3.0);
  const Eigen::Vector2d z(0.3, -0.2);
  std::array<double, 3> xm{0.1, 0.2, 7.0};
  std::array<double, 2> xk{0.5, 0.4}, xl{-0.5, 0.1}, xm_seen{0.1, 0.2};
  const auto prior_a = marginalize(
      {{relative(A, z, 3), {xm.data(), xk.data()}}, {relative(B, z, 3), {xm.data(), xl.data()}}},
      {xm.data()});
  const std::vector<Term> seen = {{relative(A, z), {xm_seen.data(), xk.data()}},
                                  {relative(B, z), {xm_seen.data(), xl.data()}}};
  expectPrior(prior_a,
              schur(evaluateWithCeres(*problemOf(seen), {xm_seen.data(), xk.data(), xl.data()}), 2),
              1e-9);
  EXPECT_TRUE(prior_a->J.allFinite() && prior_a->r0.allFinite());

  // (b) Gauge freedom: only relative residuals, so H* has the translation of x1, x2 in its null
  // space. The prior keeps the 2 observable directions and no NaN from S^-1/2.
  std::array<double, 2> x0{0.0, 0.0}, x1{1.0, 0.2}, x2{2.0, -0.1};
  const auto prior_b = marginalize(
      {{relative(A, z), {x0.data(), x1.data()}}, {relative(B, z), {x0.data(), x2.data()}}},
      {x0.data()});
  ASSERT_NE(prior_b, nullptr);
  EXPECT_EQ(prior_b->J.rows(), 2);
  EXPECT_TRUE(prior_b->J.allFinite() && prior_b->r0.allFinite());
  const Eigen::MatrixXd H = prior_b->information();
  EXPECT_GE(minEigenvalue(H), -1e-12 * H.cwiseAbs().maxCoeff());
  Eigen::MatrixXd translation(4, 2);
  translation << Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Identity();
  EXPECT_LT((prior_b->J * translation).cwiseAbs().maxCoeff(), 1e-12);
}

// x0 - x1 with an outlier on the relative residual; x0 marginalised.
TEST(Marginalization, RobustLossMatchesCeresTriggsCorrection) {
  std::array<double, 2> x0{0.0, 0.0}, x1{5.0, -4.0};
  const auto terms = [&](std::shared_ptr<ceres::LossFunction> loss) -> std::vector<Term> {
    return {{absolute(upperTriangular(2.0, 0.3, 1.5), {0.1, 0.1}), {x0.data()}},
            {relative(upperTriangular(1.0, 0.2, 0.8), {1.0, 0.0}), {x0.data(), x1.data()}, loss},
            {absolute(upperTriangular(0.5, 0.0, 0.7), {5.0, -4.2}), {x1.data()}}};
  };
  const auto ceres_schur = [&](std::shared_ptr<ceres::LossFunction> loss) {
    return schur(evaluateWithCeres(*problemOf(terms(loss)), {x0.data(), x1.data()}), 2);
  };
  const auto plain = marginalize(terms(nullptr), {x0.data()});
  // Huber: rho'' <= 0 outside the core, so the correction is the sqrt(rho') weight.
  const auto huber = std::make_shared<ceres::HuberLoss>(1.0);
  const auto robust = marginalize(terms(huber), {x0.data()});
  expectPrior(robust, ceres_schur(huber), 1e-9);
  ASSERT_NE(plain, nullptr);
  const Eigen::MatrixXd reduction = plain->information() - robust->information();
  EXPECT_GE(minEigenvalue(reduction), -1e-12);
  EXPECT_GT(reduction.trace(), 0.1 * plain->information().trace());

  // TolerantLoss has rho'' > 0: the full Triggs correction (alpha != 0) must match Ceres too.
  const auto tolerant = std::make_shared<ceres::TolerantLoss>(30.0, 10.0);
  expectPrior(marginalize(terms(tolerant), {x0.data()}), ceres_schur(tolerant), 1e-9);
}

TEST(Marginalization, BadUseThrowsInvalidInput) {
  std::array<double, 2> x{0.0, 0.0}, y{1.0, 1.0}, untouched{0.0, 0.0}, nan{std::nan(""), 0.0};
  std::array<double, 3> x3{0.0, 0.0, 0.0};
  const auto rel = relative(Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero());
  const auto rel3 = relative(Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), 3);
  const Term xy = {rel, {x.data(), y.data()}};
  // A marked block no residual touches, a failing cost function, a non-finite residual.
  EXPECT_THROW((void)marginalize({xy}, {untouched.data()}), InvalidInput);
  EXPECT_THROW((void)marginalize({{std::make_shared<FailingCost>(), {x.data()}}, xy}, {x.data()}),
               InvalidInput);
  EXPECT_THROW((void)marginalize({{rel, {nan.data(), y.data()}}}, {nan.data()}), InvalidInput);
  EXPECT_EQ(marginalize({xy}, {x.data(), y.data()}), nullptr);  // nothing kept: no prior

  Marginalizer n;
  EXPECT_THROW(n.addResidualBlock(rel, nullptr, {x.data(), nullptr}), InvalidInput);
  EXPECT_THROW(n.addResidualBlock(nullptr, nullptr, {x.data(), y.data()}), InvalidInput);
  EXPECT_THROW(n.addResidualBlock(rel, nullptr, {x.data()}), InvalidInput);
  EXPECT_THROW(n.addResidualBlock(rel, nullptr, {x.data(), x.data()}), InvalidInput);
  EXPECT_THROW(n.markForRemoval(nullptr), InvalidInput);
  n.addResidualBlock(rel, nullptr, {x.data(), y.data()});
  // The same block with two sizes; a manifold whose ambient size is not the block's.
  EXPECT_THROW(n.addResidualBlock(rel3, nullptr, {x.data(), y.data()}), InvalidInput);
  ceres::QuaternionManifold quaternion;
  EXPECT_THROW(n.setManifold(x.data(), &quaternion), InvalidInput);
  n.setManifold(x3.data(), &quaternion);
  EXPECT_THROW(n.addResidualBlock(rel3, nullptr, {x3.data(), y.data()}), InvalidInput);

  EXPECT_THROW(MarginalizationFactor factor(nullptr), InvalidInput);
  EXPECT_THROW(MarginalizationFactor factor(std::make_shared<MarginalizationPrior>()),
               InvalidInput);
}

// Rotations q0..q3 with relative rotation residuals; x0 then x1 marginalised, the second time
// with the first prior as one of the residual blocks.
TEST(Marginalization, RemarginalizingPreviousPriorMatchesFullSchur) {
  std::array<Quat, 4> q = {unitQuaternion(1.0, 0.1, 0.0, 0.05), unitQuaternion(0.9, 0.2, -0.1, 0.3),
                           unitQuaternion(0.8, 0.3, 0.2, 0.1), unitQuaternion(0.7, -0.2, 0.4, 0.2)};
  const auto meas = [](double x, double y, double z) { return unitQuaternion(1.0, x, y, z); };
  const auto rel01 = rotationCost(meas(0.1, -0.2, 0.2), {3.0, 2.0, 4.0});
  const auto rel02 = rotationCost(meas(-0.1, 0.2, 0.1), {1.0, 1.5, 0.5});
  const auto rel12 = rotationCost(meas(0.05, 0.3, -0.2), {2.0, 3.0, 1.0});
  const auto rel13 = rotationCost(meas(-0.3, 0.1, 0.2), {1.0, 0.5, 2.0});
  const auto abs0 = std::make_shared<ceres::AutoDiffCostFunction<RotationResidual, 3, 4>>(
      new RotationResidual{meas(0.0, 0.1, -0.1), {5.0, 4.0, 6.0}});
  ceres::QuaternionManifold manifold;

  std::vector<Term> terms = {{abs0, {q[0].data()}},
                             {rel01, {q[0].data(), q[1].data()}},
                             {rel02, {q[0].data(), q[2].data()}}};
  const auto prior1 = marginalize(terms, {q[0].data()}, &manifold);
  ASSERT_NE(prior1, nullptr);

  Marginalizer second;  // manifolds of q1, q2 come from prior1; q3 needs its own
  second.addResidualBlock(std::make_shared<MarginalizationFactor>(prior1), nullptr,
                          {q[1].data(), q[2].data()});
  second.addResidualBlock(rel12, nullptr, {q[1].data(), q[2].data()});
  second.addResidualBlock(rel13, nullptr, {q[1].data(), q[3].data()});
  second.setManifold(q[3].data(), &manifold);
  second.markForRemoval(q[1].data());
  const auto prior2 = second.marginalize();
  ASSERT_NE(prior2, nullptr);
  ASSERT_EQ(prior2->blocks.size(), 2U);
  EXPECT_EQ(prior2->blocks[0].original_address, q[2].data());
  EXPECT_EQ(prior2->blocks[0].manifold, &manifold);  // adopted from prior1
  EXPECT_EQ(prior2->blocks[1].manifold, &manifold);
  EXPECT_EQ(prior2->J.rows(), 6);

  terms.push_back({rel12, {q[1].data(), q[2].data()}});
  terms.push_back({rel13, {q[1].data(), q[3].data()}});
  const Linearization expected =
      schur(evaluateWithCeres(*problemOf(terms, &manifold),
                              {q[0].data(), q[1].data(), q[2].data(), q[3].data()}),
            6);
  expectPrior(prior2, expected, 1e-9 * expected.H.cwiseAbs().maxCoeff());
}

// Leaving scalars that share residuals only with a leaving pose-like block are eliminated on their
// own (odometry/schur_complement.hpp); two that share a residual with each other must not be.
// Either way the prior is the Schur complement of all leaving blocks at once.
TEST(Marginalization, LeavingBlocksThatShareResidualsAreEliminatedTogether) {
  std::array<double, 1> a{0.3}, b{-0.2}, c{1.1};
  std::array<double, 2> p{0.5, -0.4}, k1{0.1, 0.2}, k2{-0.3, 0.7};
  const auto cost = [](std::vector<Eigen::MatrixXd> A, int rows, double shift) {
    Eigen::VectorXd z(rows);
    for (int i = 0; i < rows; ++i) z(i) = shift + 0.1 * i;
    for (std::size_t k = 0; k < A.size(); ++k) {
      for (Eigen::Index i = 0; i < A[k].size(); ++i) {
        A[k](i) = 1.0 + 0.37 * static_cast<double>(k + 1) *
                            std::sin(1.7 * static_cast<double>(i) + shift);
      }
    }
    return std::make_shared<LinearCost>(std::move(A), z);
  };
  const auto block = [](int rows, int cols) { return Eigen::MatrixXd(rows, cols); };
  const std::vector<Term> terms = {
      {cost({block(2, 1), block(2, 2), block(2, 2)}, 2, 0.1), {a.data(), p.data(), k1.data()}},
      {cost({block(2, 1), block(2, 2), block(2, 2)}, 2, 0.4), {b.data(), p.data(), k2.data()}},
      {cost({block(1, 1), block(1, 1)}, 1, 0.9), {a.data(), b.data()}},
      {cost({block(1, 1)}, 1, 1.3), {c.data()}},
      {cost({block(2, 1), block(2, 2)}, 2, 1.6), {c.data(), k1.data()}},
      {cost({block(4, 2), block(4, 2), block(4, 2)}, 4, 2.2), {p.data(), k1.data(), k2.data()}},
      {cost({block(1, 1)}, 1, 2.9), {a.data()}},
      {cost({block(1, 1)}, 1, 3.4), {b.data()}}};
  const auto prior = marginalize(terms, {a.data(), b.data(), c.data(), p.data()});
  const Linearization expected =
      schur(evaluateWithCeres(*problemOf(terms),
                              {a.data(), p.data(), b.data(), c.data(), k1.data(), k2.data()}),
            5);
  expectPrior(prior, expected, 1e-9 * expected.H.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace gvio::odometry

namespace gvio::odometry {
namespace {

// A prior on two Euclidean scalars a and b: r = r0 + J [da, db].
std::shared_ptr<MarginalizationPrior> twoScalarPrior(const double* a, const double* b) {
  auto p = std::make_shared<MarginalizationPrior>();
  for (const double* block : {a, b}) {
    MarginalizationPrior::Block blk;
    blk.original_address = block;
    blk.ambient_size = blk.tangent_size = 1;
    blk.x0 = {*block};
    p->blocks.push_back(blk);
  }
  p->J = upperTriangular(4.0, -1.5, 2.0);
  p->r0 = Eigen::Vector2d(0.7, -0.3);
  return p;
}

TEST(MarginalizationRandomWalk, AddsTheVarianceToOneCoordinateAndKeepsTheMean) {
  const double a = 1.0, b = -2.0;
  const auto prior = twoScalarPrior(&a, &b);
  const double q = 0.09;
  const auto walked = withRandomWalk(prior, &b, 0, q);
  ASSERT_NE(walked, nullptr);
  const Eigen::Matrix2d sigma = prior->information().inverse();
  Eigen::Matrix2d expected = sigma;
  expected(1, 1) += q;  // Sigma + q e_b e_b^T
  const Eigen::Matrix2d sigma_walked = walked->information().inverse();
  EXPECT_LT((sigma_walked - expected).norm(), 1e-12) << sigma_walked;
  // The minimiser of |r0 + J dx|^2 (the prior's mean) does not move.
  const Eigen::Vector2d mean = -prior->J.colPivHouseholderQr().solve(prior->r0);
  const Eigen::Vector2d mean_walked =
      -(walked->J.transpose() * walked->J).ldlt().solve(walked->J.transpose() * walked->r0);
  EXPECT_LT((mean_walked - mean).norm(), 1e-12);
  EXPECT_EQ(walked->blocks.size(), 2U);
  EXPECT_EQ(walked->blocks[1].x0, prior->blocks[1].x0);
}

TEST(MarginalizationRandomWalk, ZeroVarianceKeepsThePriorAndBadRequestsThrow) {
  const double a = 1.0, b = -2.0, c = 3.0;
  const auto prior = twoScalarPrior(&a, &b);
  EXPECT_EQ(withRandomWalk(prior, &a, 0, 0.0), prior);
  EXPECT_THROW((void)withRandomWalk(prior, &c, 0, 1.0), InvalidInput);
  EXPECT_THROW((void)withRandomWalk(prior, &a, 1, 1.0), InvalidInput);
  EXPECT_THROW((void)withRandomWalk(prior, &a, 0, -1.0), InvalidInput);
  EXPECT_THROW((void)withRandomWalk(prior, &a, 0, NAN), InvalidInput);
  EXPECT_THROW((void)withRandomWalk(nullptr, &a, 0, 1.0), InvalidInput);
}

}  // namespace
}  // namespace gvio::odometry
