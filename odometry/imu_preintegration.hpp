#pragma once
// On-manifold IMU preintegration between two keyframes i and j: Forster, Carlone, Dellaert,
// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial Odometry", IEEE T-RO 2017.
// Equation numbers below refer to that paper.
//
// Measurement model (eq. 27-28): gyr = omega_b + b_g + eta_g, acc = R_w_b^T (a_w - g_w) + b_a +
// eta_a. The preintegrated deltas dR, dv, dp are independent of the states at i and j (eq. 33):
//   R_j = R_i dR,  v_j = v_i + g_w dt + R_i dv,  p_j = p_i + v_i dt + 0.5 g_w dt^2 + R_i dp.
//
// Conventions: R = R_w_b (body to world), p and v of the body in the world. Error-state order is
// (dphi, dv, dp) for the deltas, the residual and the 9x9 covariance. State perturbations are
// applied on the right/body side as in eq. 65ff.: R <- R Exp(dphi), p <- p + R dp, v <- v + dv,
// b <- b + db.
#include <Eigen/Core>
#include <vector>

#include "odometry/measurements.hpp"

namespace gvio::odometry {

struct ImuBias {
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();  // m/s^2
  Eigen::Vector3d gyr = Eigen::Vector3d::Zero();  // rad/s
};

class ImuPreintegration {
 public:
  using Matrix9d = Eigen::Matrix<double, 9, 9>;
  using Vector9d = Eigen::Matrix<double, 9, 1>;
  using Jacobian9x24 = Eigen::Matrix<double, 9, 24>;

  // Column blocks of residualJacobians(): each 3 wide, starting at these columns.
  static constexpr int kColPhiI = 0, kColPI = 3, kColVI = 6;
  static constexpr int kColPhiJ = 9, kColPJ = 12, kColVJ = 15;
  static constexpr int kColBiasAcc = 18, kColBiasGyr = 21;
  // Row blocks of the residual, the deltas' covariance and the error state.
  static constexpr int kRowR = 0, kRowV = 3, kRowP = 6;

  // Throws InvalidInput for invalid noise densities or a non-finite bias.
  ImuPreintegration(const ImuBias& linearization_bias, const ImuNoise& noise);

  // Adds the interval [a.t_ns, b.t_ns] with the midpoint of the two samples (acc, gyr averaged).
  // Throws InvalidInput unless b.t_ns > a.t_ns and the samples are finite.
  void integrate(const ImuSample& a, const ImuSample& b);
  // Adds dt_s seconds of constant acc_b (m/s^2) and gyr_b (rad/s). Throws InvalidInput unless
  // dt_s > 0 and every value is finite.
  void integrate(double dt_s, const Eigen::Vector3d& acc_b, const Eigen::Vector3d& gyr_b);

  // Total integrated time (s) and deltas at the linearisation bias (eq. 35).
  [[nodiscard]] double deltaT() const { return delta_t_; }
  [[nodiscard]] const Eigen::Matrix3d& deltaR() const { return delta_R_; }
  [[nodiscard]] const Eigen::Vector3d& deltaV() const { return delta_v_; }
  [[nodiscard]] const Eigen::Vector3d& deltaP() const { return delta_p_; }

  // Covariance of the preintegration noise (dphi, dv, dp), eq. 62-63.
  [[nodiscard]] const Matrix9d& covariance() const { return covariance_; }
  // Covariance of the bias change over deltaT() from the random walks (acc then gyr), for a
  // bias residual between i and j: sigma^2 = random_walk^2 * deltaT (Forster eq. 48).
  [[nodiscard]] Eigen::Matrix<double, 6, 6> biasRandomWalkCovariance() const;

  // Bias Jacobians of the deltas at the linearisation bias (eq. 69-70, appendix B).
  [[nodiscard]] const Eigen::Matrix3d& dR_dbg() const { return dR_dbg_; }
  [[nodiscard]] const Eigen::Matrix3d& dV_dba() const { return dv_dba_; }
  [[nodiscard]] const Eigen::Matrix3d& dV_dbg() const { return dv_dbg_; }
  [[nodiscard]] const Eigen::Matrix3d& dP_dba() const { return dp_dba_; }
  [[nodiscard]] const Eigen::Matrix3d& dP_dbg() const { return dp_dbg_; }

  [[nodiscard]] const ImuBias& linearizationBias() const { return linearization_bias_; }
  [[nodiscard]] const ImuNoise& noise() const { return noise_; }
  [[nodiscard]] std::size_t intervalCount() const { return intervals_.size(); }

  // First-order bias correction (eq. 44): deltas for a bias b near the linearisation point.
  [[nodiscard]] Eigen::Matrix3d correctedDeltaR(const ImuBias& b) const;
  [[nodiscard]] Eigen::Vector3d correctedDeltaV(const ImuBias& b) const;
  [[nodiscard]] Eigen::Vector3d correctedDeltaP(const ImuBias& b) const;

  // True when b is further than the thresholds (Euclidean norms, m/s^2 and rad/s) from the
  // linearisation bias, so that the first-order correction is inaccurate.
  [[nodiscard]] bool needsReintegration(const ImuBias& b, double acc_threshold = 0.1,
                                        double gyr_threshold = 0.01) const;
  // Repeats the integration of the stored intervals at a new linearisation bias.
  void reintegrate(const ImuBias& new_linearization_bias);

  // 9-D residual (r_dR, r_dv, r_dp) of the states at i and j with bias_i (eq. 45):
  //   r_dR = Log(dR(b)^T R_i^T R_j)
  //   r_dv = R_i^T (v_j - v_i - g_w dt) - dv(b)
  //   r_dp = R_i^T (p_j - p_i - v_i dt - 0.5 g_w dt^2) - dp(b)
  [[nodiscard]] Vector9d residual(const Eigen::Matrix3d& R_i, const Eigen::Vector3d& p_i,
                                  const Eigen::Vector3d& v_i, const Eigen::Matrix3d& R_j,
                                  const Eigen::Vector3d& p_j, const Eigen::Vector3d& v_j,
                                  const ImuBias& bias_i, const Eigen::Vector3d& g_w) const;

  // Analytic Jacobian of residual() w.r.t. (dphi_i, dp_i, dv_i, dphi_j, dp_j, dv_j, dba, dbg)
  // (column blocks kCol*), perturbations as in the file comment (eq. 65ff., appendix C).
  void residualJacobians(const Eigen::Matrix3d& R_i, const Eigen::Vector3d& p_i,
                         const Eigen::Vector3d& v_i, const Eigen::Matrix3d& R_j,
                         const Eigen::Vector3d& p_j, const Eigen::Vector3d& v_j,
                         const ImuBias& bias_i, const Eigen::Vector3d& g_w, Jacobian9x24& J) const;

 private:
  // One raw interval of constant measurements, kept for reintegrate().
  struct Interval {
    double dt_s;
    Eigen::Vector3d acc_b, gyr_b;
  };

  void reset();
  void propagate(const Interval& interval);
  void propagateCovariance(const Eigen::Matrix3d& dR_step, const Eigen::Matrix3d& acc_hat,
                           const Eigen::Vector3d& phi_step, double dt);
  void propagateBiasJacobians(const Eigen::Matrix3d& dR_step, const Eigen::Matrix3d& acc_hat,
                              const Eigen::Vector3d& phi_step, double dt);

  ImuBias linearization_bias_;
  ImuNoise noise_;
  std::vector<Interval> intervals_;

  double delta_t_ = 0.0;
  Eigen::Matrix3d delta_R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d delta_v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_p_ = Eigen::Vector3d::Zero();
  Matrix9d covariance_ = Matrix9d::Zero();
  Eigen::Matrix3d dR_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dv_dba_ = Eigen::Matrix3d::Zero(), dv_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dp_dba_ = Eigen::Matrix3d::Zero(), dp_dbg_ = Eigen::Matrix3d::Zero();
};

}  // namespace gvio::odometry
