#include "odometry/marginalization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

#include "odometry/error.hpp"
#include "odometry/schur_complement.hpp"

namespace gvio::odometry {
namespace {

// Ceres stores Jacobians and manifold Jacobians row-major.
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

int tangentSizeOf(int ambient_size, const ceres::Manifold* manifold) {
  return manifold != nullptr ? manifold->TangentSize() : ambient_size;
}

// Robust loss rho(|r|^2) applied to a linearised residual exactly as Ceres does in
// internal/ceres/corrector.cc (Triggs et al., "Bundle Adjustment - A Modern Synthesis", 2000,
// sec. 4.3; VINS-Mono's ResidualBlockInfo::Evaluate is the same code): the corrected r~, J~ make
// 1/2 |r~ + J~ dx|^2 the second-order model of 1/2 rho(|r + J dx|^2), rho'' included where it is
// positive. Matching Ceres means the prior carries the information Ceres' own solver used.
void applyLoss(const ceres::LossFunction& loss, Eigen::VectorXd& r, Eigen::MatrixXd& J) {
  const double sq_norm = r.squaredNorm();
  double rho[3] = {0.0, 0.0, 0.0};
  loss.Evaluate(sq_norm, rho);
  if (!std::isfinite(rho[1]) || !std::isfinite(rho[2])) {
    throw InvalidInput("marginalization: loss function returned a non-finite derivative");
  }
  // rho' = 0 (e.g. Tukey beyond its cut-off): the residual carries no information. Ceres assumes
  // rho' > 0; a zero weight is the limit of its correction.
  if (rho[1] <= 0.0) {
    r.setZero();
    J.setZero();
    return;
  }
  const double sqrt_rho1 = std::sqrt(rho[1]);
  if (sq_norm == 0.0 || rho[2] <= 0.0) {
    r *= sqrt_rho1;
    J *= sqrt_rho1;
    return;
  }
  const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
  const double alpha_sq_norm = alpha / sq_norm;
  J = sqrt_rho1 * (J - alpha_sq_norm * r * (r.transpose() * J));
  r *= sqrt_rho1 / (1.0 - alpha);
}

}  // namespace

int MarginalizationPrior::tangentSize() const {
  int n = 0;
  for (const Block& b : blocks) n += b.tangent_size;
  return n;
}

std::vector<double*> MarginalizationPrior::blockAddresses() const {
  std::vector<double*> addresses;
  addresses.reserve(blocks.size());
  // The prior only reads its blocks; Ceres' interface takes them as mutable.
  for (const Block& b : blocks) addresses.push_back(const_cast<double*>(b.original_address));
  return addresses;
}

int MarginalizationPrior::blockIndex(const double* original_address) const {
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (blocks[i].original_address == original_address) return static_cast<int>(i);
  }
  return -1;
}

Marginalizer::Marginalizer(MarginalizationOptions options) : options_(options) {
  if (!(options_.eigenvalue_relative_threshold >= 0.0) ||
      !(options_.eigenvalue_absolute_threshold >= 0.0)) {
    throw InvalidInput("marginalization: eigenvalue thresholds must be >= 0");
  }
}

Marginalizer::BlockState& Marginalizer::state(const double* block) {
  if (block == nullptr) throw InvalidInput("marginalization: null parameter block");
  return blocks_[block];
}

void Marginalizer::setManifold(const double* block, const ceres::Manifold* manifold) {
  BlockState& s = state(block);
  if (manifold != nullptr && s.ambient_size != 0 && manifold->AmbientSize() != s.ambient_size) {
    throw InvalidInput("marginalization: manifold ambient size " +
                       std::to_string(manifold->AmbientSize()) + " does not match block size " +
                       std::to_string(s.ambient_size));
  }
  s.manifold = manifold;
  s.manifold_owner.reset();
}

void Marginalizer::setManifold(const double* block,
                               std::shared_ptr<const ceres::Manifold> manifold) {
  setManifold(block, manifold.get());
  blocks_[block].manifold_owner = std::move(manifold);
}

const ceres::Manifold* Marginalizer::manifold(const double* block) const {
  const auto it = blocks_.find(block);
  return it == blocks_.end() ? nullptr : it->second.manifold;
}

void Marginalizer::addResidualBlock(std::shared_ptr<const ceres::CostFunction> cost,
                                    std::shared_ptr<const ceres::LossFunction> loss,
                                    std::vector<double*> blocks) {
  if (cost == nullptr) throw InvalidInput("marginalization: null cost function");
  const std::vector<std::int32_t>& sizes = cost->parameter_block_sizes();
  if (sizes.size() != blocks.size()) {
    throw InvalidInput("marginalization: cost function has " + std::to_string(sizes.size()) +
                       " parameter blocks, " + std::to_string(blocks.size()) + " given");
  }
  if (cost->num_residuals() <= 0) {
    throw InvalidInput("marginalization: cost function without residuals");
  }
  ResidualEntry entry{std::move(cost), std::move(loss), {}};
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const double* block = blocks[i];
    if (block == nullptr) throw InvalidInput("marginalization: null parameter block");
    if (sizes[i] <= 0) throw InvalidInput("marginalization: parameter block of size <= 0");
    if (std::find(entry.blocks.begin(), entry.blocks.end(), block) != entry.blocks.end()) {
      throw InvalidInput("marginalization: parameter block repeated in one residual block");
    }
    // Validate against the known state before registering anything, so a throw leaves the
    // marginaliser unchanged apart from blocks that only setManifold/markForRemoval named.
    const auto it = blocks_.find(block);
    if (it != blocks_.end()) {
      const BlockState& s = it->second;
      if (s.ambient_size != 0 && s.ambient_size != sizes[i]) {
        throw InvalidInput("marginalization: parameter block seen with sizes " +
                           std::to_string(s.ambient_size) + " and " + std::to_string(sizes[i]));
      }
      if (s.manifold != nullptr && s.manifold->AmbientSize() != sizes[i]) {
        throw InvalidInput("marginalization: manifold ambient size does not match block size " +
                           std::to_string(sizes[i]));
      }
    }
    entry.blocks.push_back(block);
  }
  // A previous prior knows its blocks' manifolds: blocks without one adopt them (setManifold may
  // still override), so re-marginalising cannot silently treat a quaternion as Euclidean.
  const auto* previous = dynamic_cast<const MarginalizationFactor*>(entry.cost.get());
  for (std::size_t i = 0; i < entry.blocks.size(); ++i) {
    BlockState& s = blocks_[entry.blocks[i]];
    if (s.ambient_size == 0) {
      s.ambient_size = sizes[i];
      order_.push_back(entry.blocks[i]);
    }
    if (previous != nullptr && s.manifold == nullptr) {
      s.manifold = previous->prior().blocks[i].manifold;
      s.manifold_owner = previous->prior().blocks[i].manifold_owner;
    }
  }
  residuals_.push_back(std::move(entry));
}

void Marginalizer::markForRemoval(const double* block) {
  state(block).remove = true;
}

std::vector<LeavingBlock> Marginalizer::leavingBlocks(
    const std::unordered_map<const double*, int>& offset) const {
  std::vector<const double*> leaving;
  for (const double* block : order_) {
    if (blocks_.at(block).remove) leaving.push_back(block);
  }
  std::unordered_map<const double*, std::vector<const double*>> shares;
  std::vector<const double*> named;
  for (const ResidualEntry& res : residuals_) {
    named.clear();
    for (const double* block : res.blocks) {
      if (blocks_.at(block).remove) named.push_back(block);
    }
    for (const double* a : named) {
      for (const double* b : named) {
        if (a != b) shares[a].push_back(b);
      }
    }
  }
  const auto tangent = [&](const double* block) {
    const BlockState& s = blocks_.at(block);
    return tangentSizeOf(s.ambient_size, s.manifold);
  };
  std::vector<const double*> by_size = leaving;
  std::stable_sort(by_size.begin(), by_size.end(),
                   [&](const double* a, const double* b) { return tangent(a) < tangent(b); });
  std::unordered_set<const double*> isolated;
  for (const double* block : by_size) {
    const auto it = shares.find(block);
    const bool alone = it == shares.end() ||
                       std::none_of(it->second.begin(), it->second.end(),
                                    [&](const double* other) { return isolated.count(other) > 0; });
    if (alone) isolated.insert(block);
  }
  std::vector<LeavingBlock> out;
  out.reserve(leaving.size());
  for (const double* block : leaving) {
    out.push_back({offset.at(block), tangent(block), isolated.count(block) > 0});
  }
  return out;
}

std::shared_ptr<const MarginalizationPrior> Marginalizer::marginalize() const {
  for (const auto& [block, s] : blocks_) {
    if (s.remove && s.ambient_size == 0) {
      throw InvalidInput("marginalization: a block marked for removal is in no residual block");
    }
  }

  // Tangent columns: removed blocks first (m), then kept blocks (r), each in first-seen order.
  std::unordered_map<const double*, int> offset;
  int m = 0;
  int n = 0;
  for (const bool removed : {true, false}) {
    for (const double* block : order_) {
      const BlockState& s = blocks_.at(block);
      if (s.remove != removed) continue;
      offset[block] = n;
      n += tangentSizeOf(s.ambient_size, s.manifold);
    }
    if (removed) m = n;
  }
  if (n == m) return nullptr;

  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  for (const ResidualEntry& res : residuals_) {
    const int rows = res.cost->num_residuals();
    const std::size_t k = res.blocks.size();
    std::vector<RowMatrix> ambient(k);
    std::vector<double*> jac_ptrs(k);
    std::vector<int> local_offset(k + 1, 0);
    for (std::size_t i = 0; i < k; ++i) {
      const BlockState& s = blocks_.at(res.blocks[i]);
      ambient[i].resize(rows, s.ambient_size);
      jac_ptrs[i] = ambient[i].data();
      local_offset[i + 1] = local_offset[i] + tangentSizeOf(s.ambient_size, s.manifold);
    }
    Eigen::VectorXd r(rows);
    if (!res.cost->Evaluate(res.blocks.data(), r.data(), jac_ptrs.data())) {
      throw InvalidInput("marginalization: a cost function failed to evaluate");
    }
    // Jacobians in the tangent space, as Ceres' evaluator forms them: J_ambient * PlusJacobian.
    Eigen::MatrixXd J(rows, local_offset[k]);
    for (std::size_t i = 0; i < k; ++i) {
      const BlockState& s = blocks_.at(res.blocks[i]);
      const int tangent = local_offset[i + 1] - local_offset[i];
      if (s.manifold == nullptr) {
        J.middleCols(local_offset[i], tangent) = ambient[i];
        continue;
      }
      if (s.manifold->AmbientSize() != s.ambient_size) {
        throw InvalidInput("marginalization: manifold ambient size does not match block size");
      }
      RowMatrix tangent_jac(rows, tangent);
      if (!s.manifold->RightMultiplyByPlusJacobian(res.blocks[i], rows, ambient[i].data(),
                                                   tangent_jac.data())) {
        throw InvalidInput("marginalization: manifold PlusJacobian failed");
      }
      J.middleCols(local_offset[i], tangent) = tangent_jac;
    }
    if (const auto* previous = dynamic_cast<const MarginalizationFactor*>(res.cost.get())) {
      for (std::size_t i = 0; i < k; ++i) {
        if (local_offset[i + 1] - local_offset[i] != previous->prior().blocks[i].tangent_size) {
          throw InvalidInput("marginalization: block manifold differs from the previous prior's");
        }
      }
    }
    if (!r.allFinite() || !J.allFinite()) {
      throw InvalidInput("marginalization: non-finite residual or Jacobian");
    }
    if (res.loss != nullptr) applyLoss(*res.loss, r, J);

    const Eigen::MatrixXd H_local = J.transpose() * J;
    const Eigen::VectorXd g_local = J.transpose() * r;
    for (std::size_t a = 0; a < k; ++a) {
      const int oa = offset.at(res.blocks[a]);
      const int ta = local_offset[a + 1] - local_offset[a];
      g.segment(oa, ta) += g_local.segment(local_offset[a], ta);
      for (std::size_t b = 0; b < k; ++b) {
        const int tb = local_offset[b + 1] - local_offset[b];
        H.block(oa, offset.at(res.blocks[b]), ta, tb) +=
            H_local.block(local_offset[a], local_offset[b], ta, tb);
      }
    }
  }

  const int nr = n - m;
  const SchurComplement star = schurComplement(H, g, m, leavingBlocks(offset), options_);
  const Eigen::MatrixXd& H_star = star.H;
  const Eigen::VectorXd& g_star = star.g;

  // H* = V S V^T -> J* = S^1/2 V^T, r0 = S^-1/2 V^T g*. Dropping the null space of H* (gauge
  // directions) keeps r0 finite; J*^T r0 is g* projected onto the range of H*.
  const double scale = H.bottomRightCorner(nr, nr).diagonal().maxCoeff();
  const Spectrum rr = significantSpectrum(H_star, std::max(scale, 0.0), options_);
  if (rr.s.size() == 0) return nullptr;

  auto prior = std::make_shared<MarginalizationPrior>();
  prior->J = rr.s.cwiseSqrt().asDiagonal() * rr.V.transpose();
  prior->r0 = rr.s.cwiseSqrt().cwiseInverse().asDiagonal() * (rr.V.transpose() * g_star);
  for (const double* block : order_) {
    const BlockState& s = blocks_.at(block);
    if (s.remove) continue;
    MarginalizationPrior::Block b;
    b.original_address = block;
    b.ambient_size = s.ambient_size;
    b.tangent_size = tangentSizeOf(s.ambient_size, s.manifold);
    b.manifold = s.manifold;
    b.manifold_owner = s.manifold_owner;
    b.x0.assign(block, block + s.ambient_size);
    prior->blocks.push_back(std::move(b));
  }
  return prior;
}

std::shared_ptr<const MarginalizationPrior> withRandomWalk(
    const std::shared_ptr<const MarginalizationPrior>& prior, const double* block, int coordinate,
    double variance, const MarginalizationOptions& options) {
  if (!prior) throw InvalidInput("marginalization: random walk on a null prior");
  const int index = prior->blockIndex(block);
  if (index < 0) throw InvalidInput("marginalization: random walk on a block the prior lacks");
  if (coordinate < 0 || coordinate >= prior->blocks[index].tangent_size) {
    throw InvalidInput("marginalization: random walk coordinate outside the block");
  }
  if (!std::isfinite(variance) || variance < 0.0) {
    throw InvalidInput("marginalization: random walk variance must be finite and >= 0");
  }
  if (variance == 0.0) return prior;
  int column = coordinate;
  for (int k = 0; k < index; ++k) column += prior->blocks[k].tangent_size;
  const Eigen::MatrixXd H = prior->information();
  const Eigen::VectorXd g = prior->J.transpose() * prior->r0;
  const Eigen::VectorXd h = H.col(column);
  const double s = H(column, column) + 1.0 / variance;
  const Eigen::MatrixXd H_walked = H - h * h.transpose() / s;
  const Eigen::VectorXd g_walked = g - h * (g(column) / s);
  const Spectrum spectrum =
      significantSpectrum(H_walked, std::max(H.diagonal().maxCoeff(), 0.0), options);
  if (spectrum.s.size() == 0) return nullptr;
  auto walked = std::make_shared<MarginalizationPrior>(*prior);
  walked->J = spectrum.s.cwiseSqrt().asDiagonal() * spectrum.V.transpose();
  walked->r0 =
      spectrum.s.cwiseSqrt().cwiseInverse().asDiagonal() * (spectrum.V.transpose() * g_walked);
  return walked;
}

MarginalizationFactor::MarginalizationFactor(std::shared_ptr<const MarginalizationPrior> prior)
    : prior_(std::move(prior)) {
  if (prior_ == nullptr) throw InvalidInput("marginalization: null prior");
  const MarginalizationPrior& p = *prior_;
  if (p.blocks.empty() || p.J.rows() == 0 || p.r0.size() != p.J.rows()) {
    throw InvalidInput("marginalization: empty or inconsistent prior");
  }
  int col = 0;
  for (const MarginalizationPrior::Block& b : p.blocks) {
    const bool sizes_ok = b.ambient_size > 0 && b.tangent_size >= 0 &&
                          b.x0.size() == static_cast<std::size_t>(b.ambient_size) &&
                          (b.manifold == nullptr ? b.tangent_size == b.ambient_size
                                                 : b.manifold->AmbientSize() == b.ambient_size &&
                                                       b.manifold->TangentSize() == b.tangent_size);
    if (!sizes_ok) throw InvalidInput("marginalization: inconsistent prior block");
    offsets_.push_back(col);
    col += b.tangent_size;
    mutable_parameter_block_sizes()->push_back(b.ambient_size);
  }
  if (col != p.J.cols()) throw InvalidInput("marginalization: prior J has the wrong width");
  set_num_residuals(static_cast<int>(p.J.rows()));
}

bool MarginalizationFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const MarginalizationPrior& p = *prior_;
  Eigen::VectorXd dx(p.J.cols());
  for (std::size_t i = 0; i < p.blocks.size(); ++i) {
    const MarginalizationPrior::Block& b = p.blocks[i];
    double* d = dx.data() + offsets_[i];
    // At the linearisation point itself the residual is exactly r0: a quaternion Minus(x0, x0)
    // is only zero to round-off.
    if (std::equal(b.x0.begin(), b.x0.end(), parameters[i])) {
      std::fill(d, d + b.tangent_size, 0.0);
    } else if (b.manifold != nullptr) {
      if (!b.manifold->Minus(parameters[i], b.x0.data(), d)) return false;
    } else {
      for (int j = 0; j < b.ambient_size; ++j)
        d[j] = parameters[i][j] - b.x0[static_cast<std::size_t>(j)];
    }
  }
  Eigen::Map<Eigen::VectorXd>(residuals, p.J.rows()) = p.r0 + p.J * dx;
  if (jacobians == nullptr) return true;

  for (std::size_t i = 0; i < p.blocks.size(); ++i) {
    if (jacobians[i] == nullptr) continue;
    const MarginalizationPrior::Block& b = p.blocks[i];
    Eigen::Map<RowMatrix> out(jacobians[i], p.J.rows(), b.ambient_size);
    const auto J_block = p.J.middleCols(offsets_[i], b.tangent_size);
    if (b.manifold == nullptr) {
      out = J_block;
      continue;
    }
    // First-estimate Jacobian: J_block * MinusJacobian(x), so that Ceres' chain rule with
    // PlusJacobian(x) returns J_block (MinusJacobian * PlusJacobian = I), not the derivative of
    // Minus(x, x0) at x (VINS-Mono feeds the fixed linearized_jacobians to Ceres the same way).
    RowMatrix minus_jac(b.tangent_size, b.ambient_size);
    if (!b.manifold->MinusJacobian(parameters[i], minus_jac.data())) return false;
    out = J_block * minus_jac;
  }
  return true;
}

}  // namespace gvio::odometry
