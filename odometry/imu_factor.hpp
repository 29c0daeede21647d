#pragma once
// IMU residual between keyframes i and j (Forster et al. 2017, eq. 45 and the bias random walk,
// eq. 48) for Ceres, whitened by the square-root information of the preintegration covariance.
// Parameter blocks: pose_i (7, PoseManifold), speed_bias_i (9: v_w, b_acc, b_gyr), pose_j,
// speed_bias_j. Residual (15): r_dR, r_dv, r_dp, b_acc_j - b_acc_i, b_gyr_j - b_gyr_i.
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <memory>

#include "odometry/imu_preintegration.hpp"

namespace gvio::odometry {

inline constexpr int kSpeedBiasSize = 9;
inline constexpr int kImuResidualSize = 15;

class ImuFactor final
    : public ceres::SizedCostFunction<kImuResidualSize, 7, kSpeedBiasSize, 7, kSpeedBiasSize> {
 public:
  using Matrix15d = Eigen::Matrix<double, kImuResidualSize, kImuResidualSize>;
  using Vector15d = Eigen::Matrix<double, kImuResidualSize, 1>;

  // The preintegration is shared, not copied: the estimator re-integrates it in place when the bias
  // moves far (the whitening is fixed at construction). g_w: gravity in the world frame.
  ImuFactor(std::shared_ptr<const ImuPreintegration> preintegration, const Eigen::Vector3d& g_w);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // Unwhitened residual (for tests and diagnostics).
  [[nodiscard]] Vector15d rawResidual(double const* const* parameters) const;
  [[nodiscard]] const Matrix15d& sqrtInformation() const { return sqrt_information_; }

 private:
  std::shared_ptr<const ImuPreintegration> preintegration_;
  Eigen::Vector3d g_w_;
  Matrix15d sqrt_information_;
};

}  // namespace gvio::odometry
