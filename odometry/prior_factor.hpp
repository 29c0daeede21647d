#pragma once
// Gaussian priors that anchor a new window (the gauge) and carry initial knowledge into it: a pose
// prior with separate uncertainty for tilt (roll/pitch, which gravity makes observable) and for
// yaw and position (unobservable, held where the estimate starts), as OKVIS and OpenVINS anchor
// their first state; the speed/bias prior is a ceres::NormalPrior.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <array>

namespace gvio::odometry {

struct PoseSigmas {
  double tilt_rad = 0.01;    // roll/pitch about the world's horizontal axes
  double yaw_rad = 1e-4;     // about the world's vertical axis
  double position_m = 1e-3;  // per world axis
};

// r = S * (R0 Log(R0^T R), p - p0): rotation error expressed in the world frame so that tilt and
// yaw get their own sigma. Block: pose (7, PoseManifold).
class PosePriorFactor final : public ceres::SizedCostFunction<6, 7> {
 public:
  PosePriorFactor(const double* pose0, const PoseSigmas& sigmas);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::array<double, 7> pose0_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;  // applied to Minus(x, x0)
};

}  // namespace gvio::odometry
