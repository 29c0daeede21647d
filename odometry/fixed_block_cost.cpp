#include "odometry/fixed_block_cost.hpp"

#include <string>

#include "odometry/error.hpp"

namespace gvio::odometry {

FixedBlockCost::FixedBlockCost(std::shared_ptr<const ceres::CostFunction> inner, int held,
                               std::vector<double> value)
    : inner_(std::move(inner)), held_(held), value_(std::move(value)) {
  if (!inner_) throw InvalidInput("fixed block cost: null cost function");
  const std::vector<int>& sizes = inner_->parameter_block_sizes();
  if (held_ < 0 || held_ >= static_cast<int>(sizes.size())) {
    throw InvalidInput("fixed block cost: block " + std::to_string(held_) + " of " +
                       std::to_string(sizes.size()));
  }
  if (static_cast<int>(value_.size()) != sizes[static_cast<std::size_t>(held_)]) {
    throw InvalidInput("fixed block cost: the held value has " + std::to_string(value_.size()) +
                       " entries, the block " +
                       std::to_string(sizes[static_cast<std::size_t>(held_)]));
  }
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    if (static_cast<int>(k) != held_) mutable_parameter_block_sizes()->push_back(sizes[k]);
  }
  set_num_residuals(inner_->num_residuals());
}

bool FixedBlockCost::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const std::size_t n = inner_->parameter_block_sizes().size();
  std::vector<const double*> all(n);
  std::vector<double*> all_jacobians(n, nullptr);
  const auto held = static_cast<std::size_t>(held_);
  for (std::size_t k = 0, outer = 0; k < n; ++k) {
    if (k == held) {
      all[k] = value_.data();
      continue;
    }
    all[k] = parameters[outer];
    if (jacobians != nullptr) all_jacobians[k] = jacobians[outer];
    ++outer;
  }
  return inner_->Evaluate(all.data(), residuals,
                          jacobians != nullptr ? all_jacobians.data() : nullptr);
}

}  // namespace gvio::odometry
