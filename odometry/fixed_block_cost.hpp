#pragma once
// A cost function with one parameter block held at a given value: the inner cost's residuals and
// the Jacobians of its other blocks, the held block no longer a parameter. The marginalisation
// uses it to fold a residual in without the information it appears to give on that block (t_d
// where the motion cannot observe it, odometry/sliding_window.hpp).
#include <ceres/cost_function.h>

#include <memory>
#include <vector>

namespace gvio::odometry {

class FixedBlockCost final : public ceres::CostFunction {
 public:
  // `held` indexes the inner cost's parameter blocks; `value` (its ambient size) is copied.
  // Throws InvalidInput for a null cost, an index out of range or a value of another size.
  FixedBlockCost(std::shared_ptr<const ceres::CostFunction> inner, int held,
                 std::vector<double> value);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<const ceres::CostFunction> inner_;
  int held_;
  std::vector<double> value_;
};

}  // namespace gvio::odometry
