#pragma once
// The reference method's loosely coupled Kalman filter: the state is the 6-D error of the VIO
// position and velocity in ENU, x = (dp, dv), with continuous-time model
//   dx/dt = F x + G w,   F = [[0, I], [0, 0]],  G = I6,  w ~ N(0, diag(q_p I3, q_v I3)),
// and GNSS measurements of position and velocity, z = (p_gnss - p_vio, v_gnss - v_vio) = H x + n,
// H = I6. The corrected solution is (p_vio + dp, v_vio + dv).
#include <Eigen/Core>
#include <cstdint>

namespace gvio::fusion {

struct KfConfig {
  double q_position = 0.01;  // m^2/s: white noise density on the position error rate
  double q_velocity = 0.01;  // m^2/s^3: white noise density on the velocity error rate
  double initial_position_sigma_m = 10.0;
  double initial_velocity_sigma_mps = 1.0;
  // Scale optimistic stated sigmas by what the innovations show, per fix quality, before gating
  // (fusion/online_sigma_scale.hpp): the same screening the graph's smoother applies after the
  // drive, done causally.
  bool learn_noise = true;
  void validate() const;  // throws InvalidInput naming the field
};

class KfBaseline {
 public:
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;

  explicit KfBaseline(const KfConfig& config);

  // Propagates to t_ns (no-op for the first call, which sets the time). Exact discretisation:
  // Phi = [[I, dt I], [0, I]], Qd = integral of Phi Q Phi^T (Van Loan).
  void predict(std::int64_t t_ns);
  // Update with the measured position/velocity error and its covariance (6x6). Returns the
  // normalised innovation squared (chi-square with 6 degrees of freedom) for gating by the caller.
  double update(const Vector6d& z, const Matrix6d& R);

  [[nodiscard]] const Vector6d& state() const { return x_; }
  [[nodiscard]] const Matrix6d& covariance() const { return P_; }
  [[nodiscard]] static Matrix6d processNoise(const KfConfig& config, double dt_s);

 private:
  KfConfig config_;
  bool started_ = false;
  std::int64_t t_ns_ = 0;
  Vector6d x_ = Vector6d::Zero();
  Matrix6d P_;
};

}  // namespace gvio::fusion
