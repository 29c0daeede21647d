#pragma once
// Marginalisation of parameter blocks that leave a Ceres sliding window into a linear prior on the
// blocks that stay, by Schur complement of the Gauss-Newton system: Leutenegger et al., "Keyframe-
// based visual-inertial odometry using nonlinear optimization", IJRR 2015 (OKVIS, sec. 4.3) and
// Qin, Li, Shen, "VINS-Mono", IEEE T-RO 2018 (sec. VI-F; marginalization_factor.cpp).
//
// Linearising every residual block that touches a leaving block at the current state gives
//   1/2 sum |r_i + J_i dx|^2 = const + g^T dx + 1/2 dx^T H dx,   H = sum J_i^T J_i,  g = sum J_i^T
//   r_i
// with dx in the tangent space of each block. Minimising over the leaving part dx_m leaves
//   H* = H_rr - H_rm H_mm^+ H_mr,   g* = g_r - H_rm H_mm^+ g_m
// on the kept part dx_r, which is written back as a residual r(dx_r) = r0 + J* dx_r with
// J*^T J* = H* and J*^T r0 = g* (eigen-decomposition H* = V S V^T: J* = S^1/2 V^T, r0 = S^-1/2 V^T
// g*). (VINS calls g "b" with the same sign.) Directions with numerically zero eigenvalues, as a
// gauge freedom or a block the residuals cannot see, are dropped in both H_mm^+ and H*.
//
// First-estimate Jacobians: the prior keeps J* fixed at the linearisation point x0 (Huang et al.,
// "Observability-based rules for designing consistent EKF SLAM estimators", IJRR 2010), so the
// optimiser never sees information the prior did not have along unobservable directions.
#include <Eigen/Core>
#include <memory>
#include <unordered_map>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include "odometry/schur_complement.hpp"

namespace gvio::odometry {

// The result of one marginalisation: r(x) = r0 + J * [Minus(x_k, x0_k)]_k over the kept blocks.
struct MarginalizationPrior {
  struct Block {
    const double* original_address = nullptr;  // the block's memory when it was marginalised
    int ambient_size = 0;
    int tangent_size = 0;
    const ceres::Manifold* manifold = nullptr;  // null: Euclidean
    // Keeps `manifold` alive when it was handed over as a shared_ptr (null otherwise).
    std::shared_ptr<const ceres::Manifold> manifold_owner;
    std::vector<double> x0;  // linearisation point (ambient)
  };
  std::vector<Block> blocks;  // kept blocks, in the order residuals first named them
  Eigen::MatrixXd J;          // rank x sum(tangent_size); columns follow `blocks`
  Eigen::VectorXd r0;         // rank

  [[nodiscard]] int tangentSize() const;
  // H* = J^T J, the information the prior holds on the kept blocks' tangent spaces.
  [[nodiscard]] Eigen::MatrixXd information() const { return J.transpose() * J; }
  // The kept blocks' addresses in `blocks` order: the parameter blocks of a MarginalizationFactor
  // for an estimator whose blocks do not move.
  [[nodiscard]] std::vector<double*> blockAddresses() const;
  // Index into `blocks` of the block marginalised at `original_address`, or -1.
  [[nodiscard]] int blockIndex(const double* original_address) const;
};

struct MarginalizationOptions {
  // An eigenvalue of H_mm or H* counts as zero unless it exceeds max(absolute, relative * scale),
  // scale being the largest eigenvalue of H_mm, resp. the largest diagonal entry of H_rr (the
  // size of the round-off left by the Schur complement's cancellation). VINS uses 1e-8 absolute.
  double eigenvalue_relative_threshold = 1e-12;
  double eigenvalue_absolute_threshold = 0.0;
};

// Collects the residual blocks connected to the leaving blocks, then builds the prior. Every
// residual block added is folded into the prior (a previous prior included): the caller removes
// all of them from its problem and adds a MarginalizationFactor instead. Parameter blocks are
// identified by address and read when marginalize() runs; all of them are treated as variables.
class Marginalizer {
 public:
  explicit Marginalizer(MarginalizationOptions options = {});

  // Manifold of a block (not owned; it must outlive marginalize() and every prior and factor
  // built from it). Blocks never given one are Euclidean. Throws InvalidInput for a null block or
  // an ambient size different from the one a residual block already gave the block.
  void setManifold(const double* block, const ceres::Manifold* manifold);
  // Same, with the prior sharing ownership of the manifold (no lifetime requirement).
  void setManifold(const double* block, std::shared_ptr<const ceres::Manifold> manifold);
  // The manifold set for `block`, or null (Euclidean).
  [[nodiscard]] const ceres::Manifold* manifold(const double* block) const;

  // `blocks` are the cost function's parameter blocks in the order of parameter_block_sizes(),
  // which give their ambient sizes. `loss` may be null. Throws InvalidInput for a null cost or
  // block, a block count or size that does not match the cost function, a block repeated within
  // the residual, or a block seen before with another size. For a MarginalizationFactor (a
  // previous prior), blocks without a manifold adopt the prior's.
  void addResidualBlock(std::shared_ptr<const ceres::CostFunction> cost,
                        std::shared_ptr<const ceres::LossFunction> loss,
                        std::vector<double*> blocks);

  // Throws InvalidInput for a null block. marginalize() throws if no residual names the block.
  void markForRemoval(const double* block);

  // Evaluates every residual block at the current parameter values (tangent-space Jacobians
  // J_ambient * PlusJacobian(x), robust losses applied with Ceres' Triggs correction), forms H and
  // g, Schur-complements the marked blocks out and factorises H*. Returns nullptr when no kept
  // block remains or the kept blocks receive no information. Throws InvalidInput for a marked
  // block that no residual touches, a manifold whose ambient size does not match the block (or
  // whose tangent size differs from a previous prior's), or a cost function or loss that fails or
  // returns non-finite values at the current state.
  [[nodiscard]] std::shared_ptr<const MarginalizationPrior> marginalize() const;

 private:
  struct BlockState {
    int ambient_size = 0;  // 0 until a residual block names the block
    const ceres::Manifold* manifold = nullptr;
    std::shared_ptr<const ceres::Manifold> manifold_owner;
    bool remove = false;
  };
  struct ResidualEntry {
    std::shared_ptr<const ceres::CostFunction> cost;
    std::shared_ptr<const ceres::LossFunction> loss;
    std::vector<const double*> blocks;
  };

  BlockState& state(const double* block);
  // The leaving blocks in column order (`offset`: first tangent column of each block), those
  // that share no residual with one another marked isolated: greedily, smallest first, so that
  // every landmark's inverse depth is isolated and the oldest pose it shares residuals with is not.
  [[nodiscard]] std::vector<LeavingBlock> leavingBlocks(
      const std::unordered_map<const double*, int>& offset) const;

  MarginalizationOptions options_;
  std::unordered_map<const double*, BlockState> blocks_;
  std::vector<const double*> order_;  // blocks in the order residual blocks first named them
  std::vector<ResidualEntry> residuals_;
};

// The prior with a random walk of `variance` added to one tangent coordinate of a kept block
// since its linearisation: the covariance becomes Sigma + q e e^T, i.e. by the Woodbury identity
//   H' = H - h h^T / s,  g' = g - h (e^T g) / s,  h = H e,  s = e^T H e + 1/q,
// the information the prior holds on that coordinate (and through it on the rest) decaying while
// the mean stays (the prior's x0 is kept). Returns the prior unchanged for variance 0, nullptr
// when no information is left. Throws
// InvalidInput for a block the prior does not hold, a coordinate outside its tangent space or a
// negative or non-finite variance.
[[nodiscard]] std::shared_ptr<const MarginalizationPrior> withRandomWalk(
    const std::shared_ptr<const MarginalizationPrior>& prior, const double* block, int coordinate,
    double variance, const MarginalizationOptions& options = {});

// The prior as a Ceres cost function. Parameter blocks are the prior's kept blocks in the order of
// prior.blocks (possibly at new addresses: the estimator shifts its window), with their ambient
// sizes. The Jacobian w.r.t. ambient x is J_block * MinusJacobian(x) (J_block for Euclidean
// blocks), so Ceres' J_ambient * PlusJacobian(x) yields exactly J_block: the first-estimate
// Jacobian, as VINS-Mono's MarginalizationFactor. The manifold of each block in the problem should
// be the prior's (the product MinusJacobian * PlusJacobian must be the identity).
class MarginalizationFactor final : public ceres::CostFunction {
 public:
  // Throws InvalidInput for a null or inconsistent prior.
  explicit MarginalizationFactor(std::shared_ptr<const MarginalizationPrior> prior);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  [[nodiscard]] const MarginalizationPrior& prior() const { return *prior_; }
  [[nodiscard]] const std::shared_ptr<const MarginalizationPrior>& sharedPrior() const {
    return prior_;
  }

 private:
  std::shared_ptr<const MarginalizationPrior> prior_;
  std::vector<int> offsets_;  // tangent column of each block in prior_->J
};

}  // namespace gvio::odometry
