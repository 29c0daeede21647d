// The reference method's Kalman filter: steady state against the discrete algebraic Riccati
// equation solved independently (eigenvectors of the symplectic matrix, Laub 1979), statistical
// consistency on a simulated error process, and the update's information form.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <complex>
#include <random>

#include "fusion/kf_baseline.hpp"
#include "odometry/error.hpp"

namespace gvio::fusion {
namespace {

using Matrix2d = Eigen::Matrix2d;

// A priori steady-state covariance of one axis (position, velocity error) for
// x+ = Phi x + w (cov Q), z = x + v (cov R), from the stable invariant subspace of
//   Z = [[a + b r^-1 b^T a^-T q, -b r^-1 b^T a^-T], [-a^-T q, a^-T]],  a = Phi^T, b = I:
// X = U2 U1^-1 for the eigenvectors [U1; U2] of the eigenvalues inside the unit circle.
Matrix2d riccatiSteadyState(const Matrix2d& Phi, const Matrix2d& Q, const Matrix2d& R) {
  const Matrix2d a = Phi.transpose();
  const Matrix2d a_inv_t = a.inverse().transpose();
  const Matrix2d r_inv = R.inverse();
  Eigen::Matrix4d Z;
  Z << a + r_inv * a_inv_t * Q, -r_inv * a_inv_t, -a_inv_t * Q, a_inv_t;
  const Eigen::EigenSolver<Eigen::Matrix4d> es(Z);
  Eigen::Matrix<std::complex<double>, 4, 2> U;
  int n = 0;
  for (int k = 0; k < 4 && n < 2; ++k) {
    if (std::abs(es.eigenvalues()(k)) < 1.0) U.col(n++) = es.eigenvectors().col(k);
  }
  EXPECT_EQ(n, 2);
  const Eigen::Matrix2cd X = U.bottomRows<2>() * U.topRows<2>().inverse();
  EXPECT_LT(X.imag().norm(), 1e-9);
  return X.real();
}

TEST(KfBaseline, SteadyStateMatchesTheRiccatiSolution) {
  KfConfig config;
  config.q_position = 0.02;
  config.q_velocity = 0.005;
  KfBaseline kf(config);
  const double dt = 1.0;  // 1 Hz GNSS
  const double sigma_p = 1.5, sigma_v = 0.3;
  KfBaseline::Matrix6d R = KfBaseline::Matrix6d::Zero();
  R.diagonal() << Eigen::Vector3d::Constant(sigma_p * sigma_p),
      Eigen::Vector3d::Constant(sigma_v * sigma_v);
  KfBaseline::Matrix6d P_prior;
  for (int k = 0; k < 500; ++k) {
    kf.predict(static_cast<std::int64_t>(k * dt * 1e9));
    P_prior = kf.covariance();
    kf.update(KfBaseline::Vector6d::Zero(), R);
  }
  Matrix2d Phi;
  Phi << 1.0, dt, 0.0, 1.0;
  const KfBaseline::Matrix6d Qd = KfBaseline::processNoise(config, dt);
  Matrix2d Q, R2;
  Q << Qd(0, 0), Qd(0, 3), Qd(3, 0), Qd(3, 3);
  R2 << R(0, 0), 0.0, 0.0, R(3, 3);
  const Matrix2d X = riccatiSteadyState(Phi, Q, R2);
  for (int axis = 0; axis < 3; ++axis) {
    Matrix2d P_axis;
    P_axis << P_prior(axis, axis), P_prior(axis, axis + 3), P_prior(axis + 3, axis),
        P_prior(axis + 3, axis + 3);
    EXPECT_LT((P_axis - X).norm(), 1e-9 * X.norm()) << "axis " << axis << "\n"
                                                    << P_axis << "\n"
                                                    << X;
  }
}

TEST(KfBaseline, UpdateIsTheInformationSum) {
  KfConfig config;
  KfBaseline kf(config);
  kf.predict(0);
  const KfBaseline::Matrix6d P0 = kf.covariance();
  KfBaseline::Matrix6d R = KfBaseline::Matrix6d::Identity() * 4.0;
  kf.update(KfBaseline::Vector6d::Ones(), R);
  const KfBaseline::Matrix6d expected = (P0.inverse() + R.inverse()).inverse();
  EXPECT_LT((kf.covariance() - expected).norm(), 1e-12 * expected.norm());
  // The estimate moves towards the measurement by P0 (P0 + R)^-1.
  const KfBaseline::Vector6d x_expected = P0 * (P0 + R).inverse() * KfBaseline::Vector6d::Ones();
  EXPECT_LT((kf.state() - x_expected).norm(), 1e-12);
}

TEST(KfBaseline, ConsistentOnASimulatedErrorProcess) {
  // A straight drive's VIO error drifting as the model says, GNSS at 1 Hz with white noise: the
  // filter's error must match its covariance (mean NEES ~ 6 for 6 states).
  KfConfig config;
  config.q_position = 0.01;
  config.q_velocity = 0.002;
  KfBaseline kf(config);
  std::mt19937_64 rng(42);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double dt = 1.0;
  const KfBaseline::Matrix6d Qd = KfBaseline::processNoise(config, dt);
  const Eigen::LLT<KfBaseline::Matrix6d> Lq(Qd);
  KfBaseline::Matrix6d R = KfBaseline::Matrix6d::Zero();
  R.diagonal() << 2.25, 2.25, 9.0, 0.04, 0.04, 0.09;
  const KfBaseline::Matrix6d Lr = R.cwiseSqrt();
  KfBaseline::Vector6d x = KfBaseline::Vector6d::Zero();
  for (int k = 0; k < 6; ++k) x(k) = n01(rng) * (k < 3 ? 10.0 : 1.0);  // initial P's spread
  Eigen::Matrix<double, 6, 6> Phi = Eigen::Matrix<double, 6, 6>::Identity();
  Phi.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  double nees_sum = 0.0;
  int count = 0;
  for (int k = 0; k < 4000; ++k) {
    if (k > 0) {
      KfBaseline::Vector6d w;
      for (int i = 0; i < 6; ++i) w(i) = n01(rng);
      x = Phi * x + Lq.matrixL() * w;
    }
    kf.predict(static_cast<std::int64_t>(k * 1e9));
    KfBaseline::Vector6d v;
    for (int i = 0; i < 6; ++i) v(i) = n01(rng);
    kf.update(x + Lr * v, R);
    if (k >= 100) {
      const KfBaseline::Vector6d e = kf.state() - x;
      nees_sum += e.dot(kf.covariance().ldlt().solve(e));
      ++count;
    }
  }
  EXPECT_NEAR(nees_sum / count, 6.0, 0.6);
}

TEST(KfBaseline, RejectsInvalidNoise) {
  KfConfig config;
  config.q_velocity = 0.0;
  EXPECT_THROW(KfBaseline{config}, InvalidInput);
}

}  // namespace
}  // namespace gvio::fusion
