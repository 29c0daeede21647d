#pragma once
// Factors of the global GNSS fusion graph (fusion/graph_fusion.hpp). Nodes are body poses in ENU on
// odometry::PoseManifold (tangent (dphi, dp), perturbation (R Exp(dphi), p + R dp)); analytic
// Jacobians are handed to Ceres as J_tangent * MinusJacobian(x), as the estimator's factors do.
#include <cstdint>
#include <map>

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvio::fusion {

// Relative motion between two nodes, T_i^-1 T_j = dT (measured: VIO motion, a loop closure),
// whitened by the square root S of its information matrix (S^T S = Sigma^-1):
//   e = (Log(dR^T R_i^T R_j), R_i^T (p_j - p_i) - dp),  r = S e.
// The measurement's covariance is therefore stated in (rotation perturbation on the right of dR,
// translation in node i's frame), the convention loop verification uses.
class RelativePoseFactor final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  // Isotropic: S = diag(1/sigma_rot x3, 1/sigma_pos x3).
  RelativePoseFactor(const Eigen::Isometry3d& T_i_j, double sigma_rot_rad, double sigma_pos_m);
  RelativePoseFactor(const Eigen::Isometry3d& T_i_j, const Matrix6d& sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The unwhitened error e at the two poses (for chi-square tests: e^T Sigma^-1 e = |r|^2).
  [[nodiscard]] Eigen::Matrix<double, 6, 1> error(const Eigen::Isometry3d& T_i,
                                                  const Eigen::Isometry3d& T_j) const;

 private:
  Eigen::Matrix3d dR_;
  Eigen::Vector3d dp_;
  Matrix6d sqrt_info_;
};

// A GNSS fix of the antenna on node i: the antenna sits at q_b in the node's body frame (the lever
// arm carried by the VIO motion from the node's time to the fix time), so
//   r = W (p_i + R_i q_b - p_enu_fix),
// W the fix's square-root information (gnssSqrtInformation: the stated ellipse; a circle gives
// W = diag(1/sigma_h, 1/sigma_h, 1/sigma_v)).
class GnssPositionFactor final : public ceres::SizedCostFunction<3, 7> {
 public:
  GnssPositionFactor(const Eigen::Vector3d& q_b, const Eigen::Vector3d& p_enu_fix,
                     const Eigen::Matrix3d& sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  [[nodiscard]] const Eigen::Matrix3d& sqrtInformation() const { return sqrt_info_; }

 private:
  Eigen::Vector3d q_b_, p_fix_;
  Eigen::Matrix3d sqrt_info_;
};

// A GNSS fix with the receiver's correlated error as a state b (fusion/gnss_smoother.hpp):
//   r = W (p_i + R_i q_b + b - p_enu_fix).
class GnssBiasedPositionFactor final : public ceres::SizedCostFunction<3, 7, 3> {
 public:
  GnssBiasedPositionFactor(const Eigen::Vector3d& q_b, const Eigen::Vector3d& p_enu_fix,
                           const Eigen::Matrix3d& sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  GnssPositionFactor position_;  // the same fix without the bias (and its W)
};

// First-order Gauss-Markov process between two bias states dt apart (Groves 2013, App. I):
//   b_j = phi b_i + w, phi = exp(-dt / tau), var(w) = sigma^2 (1 - phi^2);
//   r = (b_j - phi b_i) / sqrt(var(w)).
// With a horizontal shape S (GnssFix::shape_en) the driving noise is sigma^2 (1 - phi^2)
// blockdiag(S, 1): the receiver's slow error follows the satellites' geometry as its white noise
// does (a pseudorange bias maps into position through the same (H^T H)^-1).
class GaussMarkovFactor final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  GaussMarkovFactor(double dt_s, double tau_s, double sigma,
                    const Eigen::Matrix2d& shape_en = Eigen::Matrix2d::Identity());
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double phi_;
  Eigen::Matrix3d sqrt_info_w_;
};

// The receiver's correlated error as Gauss-Markov chains of bias states, one chain per fix
// quality: an RTK fixed, a float and a single-point solution are different error processes (a
// float epoch's metre comes from its unresolved ambiguities, a fixed epoch's centimetres do not),
// so a float bias must not be carried into the fixed epochs by a chain whose steps there are
// centimetres. Each chain starts from the bias's stationary distribution, N(0, sigma^2 I); across
// a gap in one quality it decorrelates by exp(-dt / tau). Used by the smoother and the global
// graph, which add their fixes in time order.
class ReceiverBiasChains {
 public:
  explicit ReceiverBiasChains(double tau_s) : tau_s_(tau_s) {}
  // A new receiver (another drive): every chain starts again.
  void restart() { last_.clear(); }
  // The bias state `bias` of a fix of `quality` at t_ns, sigma_b its steady-state sigma and
  // shape_en its horizontal shape (the fix's ellipse): the stationary prior at its chain's first
  // fix, else the Gauss-Markov step from the chain's last.
  void add(ceres::Problem& problem, int quality, std::int64_t t_ns, double sigma_b,
           const Eigen::Matrix2d& shape_en, double* bias);

 private:
  struct Last {
    std::int64_t t_ns;
    double* bias;
  };
  double tau_s_;
  std::map<int, Last> last_;
};

// The gravity direction in the body as the VIO (with an IMU) observes it, g_b = R_w_b^T e_z: roll
// and pitch are observable from the IMU at every pose, so a pose graph need not (and must not) move
// them with the yaw and position its loops and fixes correct (VINS-Mono's 4-DoF pose graph, Qin
// et al. 2018, sec. VIII; here a stiff 6-DoF factor instead of a reduced parameterisation):
//   r = (R_i^T e_z - g_b) / sigma  (3 residuals, rank 2: rotation about e_z is free).
class TiltFactor final : public ceres::SizedCostFunction<3, 7> {
 public:
  TiltFactor(const Eigen::Vector3d& g_b, double sigma_rad);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d g_b_;
  double inv_sigma_;
};

}  // namespace gvio::fusion
