#include "odometry/imu_preintegration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "sim/imu_synth.hpp"
#include "sim/trajectory_fit.hpp"
#include "support/numeric_jacobian.hpp"

namespace gvio::odometry {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector24d = Eigen::Matrix<double, 24, 1>;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr std::int64_t kT0Ns = 1'000'000'000'000;  // an arbitrary non-zero start
constexpr std::int64_t kNsPerS = 1'000'000'000;
const Eigen::Vector3d kGravityW(0.0, 0.0, -kGravity_mps2);

ImuBias biasPlus(ImuBias b, const Vector6d& d) {
  b.acc += d.head<3>();
  b.gyr += d.tail<3>();
  return b;
}

// Measured errors go into the test report (--gtest_output=xml) with 3 significant digits.
void recordValue(const std::string& key, double value) {
  std::ostringstream text;
  text << std::setprecision(3) << value;
  ::testing::Test::RecordProperty(key, text.str());
}

// (|a - b| / |b|), or |a - b| when b is zero.
double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const double scale = b.norm();
  return (a - b).norm() / (scale > 0.0 ? scale : 1.0);
}

// ---------------------------------------------------------------------------------------------
// Synthetic motion exciting every axis (1 s at 200 Hz), for the Jacobian checks.

ImuPreintegration integrateRichMotion(const ImuBias& linearization_bias) {
  ImuPreintegration pre(linearization_bias, ImuNoise{});
  constexpr double kDt = 0.005;
  for (int k = 0; k < 200; ++k) {
    const double t = k * kDt;
    const Eigen::Vector3d acc(1.0 + 0.5 * std::sin(3.0 * t), 0.3 * std::cos(2.0 * t),
                              kGravity_mps2 + 0.2 * std::sin(5.0 * t));
    const Eigen::Vector3d gyr(0.3 * std::sin(t), 0.2 * std::cos(1.5 * t),
                              0.5 + 0.1 * std::sin(2.0 * t));
    pre.integrate(kDt, acc, gyr);
  }
  return pre;
}

const ImuBias kLinearizationBias{Eigen::Vector3d(0.02, -0.01, 0.03),
                                 Eigen::Vector3d(0.001, 0.002, -0.001)};

// d(delta)/d(b_a, b_g) by reintegrating at b +- h e_c; rotations compared in the tangent space of
// the unperturbed dR: Log(dR^T dR(b)).
TEST(ImuPreintegration, BiasJacobiansMatchCentralDifferencesOfReintegration) {
  const ImuPreintegration pre = integrateRichMotion(kLinearizationBias);
  const Eigen::Matrix3d dR_inv = pre.deltaR().transpose();
  constexpr double kH = 1e-4;
  const auto dR = test::numericJacobian<3, 6>(
      [&](const Vector6d& d) {
        return logSo3(dR_inv * integrateRichMotion(biasPlus(kLinearizationBias, d)).deltaR());
      },
      kH);
  const auto dv = test::numericJacobian<3, 6>(
      [&](const Vector6d& d) {
        return integrateRichMotion(biasPlus(kLinearizationBias, d)).deltaV();
      },
      kH);
  const auto dp = test::numericJacobian<3, 6>(
      [&](const Vector6d& d) {
        return integrateRichMotion(biasPlus(kLinearizationBias, d)).deltaP();
      },
      kH);

  EXPECT_LT(dR.leftCols<3>().norm(), 1e-10);  // the rotation does not depend on b_a
  EXPECT_LT(relativeError(dR.rightCols<3>(), pre.dR_dbg()), 1e-5);
  EXPECT_LT(relativeError(dv.leftCols<3>(), pre.dV_dba()), 1e-5);
  EXPECT_LT(relativeError(dv.rightCols<3>(), pre.dV_dbg()), 1e-5);
  EXPECT_LT(relativeError(dp.leftCols<3>(), pre.dP_dba()), 1e-5);
  EXPECT_LT(relativeError(dp.rightCols<3>(), pre.dP_dbg()), 1e-5);
  // Non-trivial Jacobians: the check would be vacuous otherwise.
  EXPECT_GT(pre.dV_dbg().norm(), 1.0);
  EXPECT_GT(pre.dP_dbg().norm(), 0.3);
}

struct NavState {
  Eigen::Matrix3d R;
  Eigen::Vector3d p, v;
};

// Eq. 33: the state at j predicted from the state at i and the deltas at bias b.
NavState predict(const ImuPreintegration& pre, const NavState& i, const ImuBias& b) {
  const double dt = pre.deltaT();
  return {i.R * pre.correctedDeltaR(b),
          i.p + i.v * dt + 0.5 * kGravityW * dt * dt + i.R * pre.correctedDeltaP(b),
          i.v + kGravityW * dt + i.R * pre.correctedDeltaV(b)};
}

// Every block of the 9x24 Jacobian against central differences of residual() under the documented
// perturbations R <- R Exp(dphi), p <- p + R dp, v <- v + dv, b <- b + db, at states that do not
// satisfy the measurement (non-zero residual) and a bias away from the linearisation point.
TEST(ImuPreintegration, ResidualJacobianMatchesCentralDifferences) {
  const ImuPreintegration pre = integrateRichMotion(kLinearizationBias);
  Vector6d bias_offset;
  bias_offset << 0.03, -0.02, 0.01, 0.002, -0.003, 0.004;
  const ImuBias bias_i = biasPlus(kLinearizationBias, bias_offset);
  const NavState state_i{expSo3(Eigen::Vector3d(0.3, -0.2, 1.0)), Eigen::Vector3d(1.0, 2.0, 3.0),
                         Eigen::Vector3d(5.0, -1.0, 0.5)};

  for (const double miss : {0.0, 0.05, 0.8}) {  // scale of the states' deviation from eq. 33
    NavState state_j = predict(pre, state_i, bias_i);
    state_j.R = state_j.R * expSo3(miss * Eigen::Vector3d(1.0, -0.6, 0.4));
    state_j.p += miss * Eigen::Vector3d(2.0, -4.0, 1.0);
    state_j.v += miss * Eigen::Vector3d(1.0, 0.4, -2.0);

    ImuPreintegration::Jacobian9x24 J;
    pre.residualJacobians(state_i.R, state_i.p, state_i.v, state_j.R, state_j.p, state_j.v, bias_i,
                          kGravityW, J);
    const auto numeric = test::numericJacobian<9, 24>([&](const Vector24d& d) {
      const Eigen::Matrix3d R_i = state_i.R * expSo3(d.segment<3>(0));
      const Eigen::Matrix3d R_j = state_j.R * expSo3(d.segment<3>(9));
      return pre.residual(R_i, state_i.p + state_i.R * d.segment<3>(3), state_i.v + d.segment<3>(6),
                          R_j, state_j.p + state_j.R * d.segment<3>(12),
                          state_j.v + d.segment<3>(15), biasPlus(bias_i, d.segment<6>(18)),
                          kGravityW);
    });
    const double worst = (numeric - J).cwiseAbs().maxCoeff();
    EXPECT_LT(worst, 1e-6) << "miss " << miss << "\nanalytic\n" << J << "\nnumeric\n" << numeric;
    std::ostringstream key;
    key << "worst_residual_jacobian_error_miss_" << miss;
    recordValue(key.str(), worst);
  }
}

// ---------------------------------------------------------------------------------------------
// Against the simulator: a car-like drive p = (10 t, 20 sin(0.1 t), 0), yaw along the heading.

sim::ContinuousTrajectory carDrive() {
  Trajectory poses;
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.1 * k;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(10.0 * t, 20.0 * std::sin(0.1 * t), 0.0);
    T.linear() =
        Eigen::AngleAxisd(std::atan2(2.0 * std::cos(0.1 * t), 10.0), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    poses.t_ns.push_back(kT0Ns + k * kNsPerS / 10);
    poses.poses.push_back(T);
  }
  return sim::ContinuousTrajectory::fit(poses);
}

// Noise-free 100 Hz IMU of the drive with a constant bias added.
std::vector<ImuSample> driveImu(const sim::ContinuousTrajectory& drive, const ImuBias& bias = {}) {
  sim::ImuSimOptions options;
  options.add_noise = false;
  std::vector<ImuSample> imu;
  for (const sim::ImuSimSample& s : sim::synthesizeImu(drive, options, 1)) {
    imu.push_back(s.measured);
    imu.back().acc_b_mps2 += bias.acc;
    imu.back().gyr_b_radps += bias.gyr;
  }
  return imu;
}

ImuPreintegration preintegrate(const std::vector<ImuSample>& imu, std::int64_t t_i_ns,
                               std::int64_t t_j_ns, const ImuBias& linearization_bias,
                               const ImuNoise& noise = {}) {
  ImuPreintegration pre(linearization_bias, noise);
  for (std::size_t k = 0; k + 1 < imu.size(); ++k) {
    if (imu[k].t_ns >= t_i_ns && imu[k + 1].t_ns <= t_j_ns) pre.integrate(imu[k], imu[k + 1]);
  }
  return pre;
}

NavState truthAt(const sim::ContinuousTrajectory& drive, std::int64_t t_ns) {
  const sim::BodyState s = drive.at(t_ns);
  return {s.R_w_b, s.p_w, s.v_w};
}

TEST(ImuPreintegration, PredictsTheSimulatedDriveFromNoiseFreeImu) {
  const sim::ContinuousTrajectory drive = carDrive();
  const std::vector<ImuSample> imu = driveImu(drive);
  const std::int64_t t_i = kT0Ns + 2 * kNsPerS;
  const NavState truth_i = truthAt(drive, t_i);

  for (const int seconds : {1, 2}) {
    const std::int64_t t_j = t_i + seconds * kNsPerS;
    const ImuPreintegration pre = preintegrate(imu, t_i, t_j, ImuBias{});
    ASSERT_EQ(pre.intervalCount(), static_cast<std::size_t>(100 * seconds));
    EXPECT_NEAR(pre.deltaT(), seconds, 1e-12);

    const NavState truth_j = truthAt(drive, t_j);
    const NavState predicted = predict(pre, truth_i, ImuBias{});
    const double rot_deg = logSo3(predicted.R.transpose() * truth_j.R).norm() * kRadToDeg;
    const double vel_mps = (predicted.v - truth_j.v).norm();
    const double pos_m = (predicted.p - truth_j.p).norm();
    EXPECT_LT(rot_deg, 0.01) << seconds << " s";
    EXPECT_LT(vel_mps, 0.01) << seconds << " s";
    EXPECT_LT(pos_m, 0.01) << seconds << " s";

    const ImuPreintegration::Vector9d r = pre.residual(truth_i.R, truth_i.p, truth_i.v, truth_j.R,
                                                       truth_j.p, truth_j.v, ImuBias{}, kGravityW);
    EXPECT_LT(r.segment<3>(ImuPreintegration::kRowR).norm() * kRadToDeg, 0.01);
    EXPECT_LT(r.segment<3>(ImuPreintegration::kRowV).norm(), 0.01);
    EXPECT_LT(r.segment<3>(ImuPreintegration::kRowP).norm(), 0.01);

    const std::string tag = "_" + std::to_string(seconds) + "s";
    recordValue("rotation_error_deg" + tag, rot_deg);
    recordValue("velocity_error_mps" + tag, vel_mps);
    recordValue("position_error_m" + tag, pos_m);
    recordValue("residual_norm" + tag, r.norm());
  }
}

// ---------------------------------------------------------------------------------------------
// Bias correction (eq. 44) against reintegration at the true bias.

const ImuBias kTrueBias{Eigen::Vector3d(0.05, -0.04, 0.03), Eigen::Vector3d(0.004, -0.003, 0.005)};

struct DeltaErrors {
  double rot_rad, vel_mps, pos_m;
};

DeltaErrors errorsOf(const Eigen::Matrix3d& R, const Eigen::Vector3d& v, const Eigen::Vector3d& p,
                     const ImuPreintegration& reference) {
  return {logSo3(R.transpose() * reference.deltaR()).norm(), (v - reference.deltaV()).norm(),
          (p - reference.deltaP()).norm()};
}

// Errors of the zero-bias preintegration over [2 s, 4 s] of the drive with bias `scale` kTrueBias,
// first-order corrected (or not) to that bias, against a reintegration at that bias.
DeltaErrors biasCorrectionErrors(double scale, bool corrected) {
  const ImuBias bias{scale * kTrueBias.acc, scale * kTrueBias.gyr};
  const sim::ContinuousTrajectory drive = carDrive();
  const std::vector<ImuSample> imu = driveImu(drive, bias);
  const std::int64_t t_i = kT0Ns + 2 * kNsPerS, t_j = kT0Ns + 4 * kNsPerS;
  const ImuPreintegration at_zero = preintegrate(imu, t_i, t_j, ImuBias{});
  const ImuPreintegration at_truth = preintegrate(imu, t_i, t_j, bias);
  if (!corrected) return errorsOf(at_zero.deltaR(), at_zero.deltaV(), at_zero.deltaP(), at_truth);
  return errorsOf(at_zero.correctedDeltaR(bias), at_zero.correctedDeltaV(bias),
                  at_zero.correctedDeltaP(bias), at_truth);
}

TEST(ImuPreintegration, FirstOrderBiasCorrectionMatchesReintegrationToSecondOrder) {
  const DeltaErrors raw = biasCorrectionErrors(1.0, false);
  const DeltaErrors fixed = biasCorrectionErrors(1.0, true);
  const DeltaErrors fixed_half = biasCorrectionErrors(0.5, true);

  EXPECT_LT(fixed.rot_rad, 1e-3 * raw.rot_rad);
  EXPECT_LT(fixed.vel_mps, 0.01 * raw.vel_mps);
  EXPECT_LT(fixed.pos_m, 0.01 * raw.pos_m);
  EXPECT_LT(fixed.pos_m, 1e-3);
  // Second order: halving the bias offset quarters the remaining error.
  EXPECT_NEAR(fixed.vel_mps / fixed_half.vel_mps, 4.0, 0.4);
  EXPECT_NEAR(fixed.pos_m / fixed_half.pos_m, 4.0, 0.4);

  recordValue("uncorrected_pos_error_m", raw.pos_m);
  recordValue("corrected_pos_error_m", fixed.pos_m);
  recordValue("uncorrected_vel_error_mps", raw.vel_mps);
  recordValue("corrected_vel_error_mps", fixed.vel_mps);
  recordValue("uncorrected_rot_error_rad", raw.rot_rad);
  recordValue("corrected_rot_error_rad", fixed.rot_rad);
  recordValue("corrected_pos_error_half_bias_m", fixed_half.pos_m);
}

TEST(ImuPreintegration, NeedsReintegrationBeyondTheThresholds) {
  const ImuPreintegration pre(kLinearizationBias, ImuNoise{});
  EXPECT_FALSE(pre.needsReintegration(kLinearizationBias));
  const auto shifted = [](double acc, double gyr) {
    ImuBias b = kLinearizationBias;
    b.acc.x() += acc;
    b.gyr.z() += gyr;
    return b;
  };
  EXPECT_FALSE(pre.needsReintegration(shifted(0.099, 0.0)));
  EXPECT_TRUE(pre.needsReintegration(shifted(0.101, 0.0)));
  EXPECT_FALSE(pre.needsReintegration(shifted(0.0, 0.0099)));
  EXPECT_TRUE(pre.needsReintegration(shifted(0.0, 0.0101)));
  EXPECT_FALSE(pre.needsReintegration(shifted(0.3, 0.03), 0.5, 0.05));
  EXPECT_TRUE(pre.needsReintegration(shifted(0.3, 0.03), 0.2, 0.05));
}

TEST(ImuPreintegration, ReintegrateEqualsIntegratingFromScratch) {
  const sim::ContinuousTrajectory drive = carDrive();
  const std::vector<ImuSample> imu = driveImu(drive, kTrueBias);
  const std::int64_t t_i = kT0Ns + 2 * kNsPerS, t_j = kT0Ns + 4 * kNsPerS;
  ImuPreintegration reintegrated = preintegrate(imu, t_i, t_j, ImuBias{});
  ASSERT_TRUE(reintegrated.needsReintegration(kTrueBias, 0.1, 0.001));
  reintegrated.reintegrate(kTrueBias);
  const ImuPreintegration scratch = preintegrate(imu, t_i, t_j, kTrueBias);

  EXPECT_EQ(reintegrated.intervalCount(), scratch.intervalCount());
  EXPECT_EQ(reintegrated.deltaT(), scratch.deltaT());
  EXPECT_EQ(reintegrated.deltaR(), scratch.deltaR());
  EXPECT_EQ(reintegrated.deltaV(), scratch.deltaV());
  EXPECT_EQ(reintegrated.deltaP(), scratch.deltaP());
  EXPECT_EQ(reintegrated.covariance(), scratch.covariance());
  EXPECT_EQ(reintegrated.dR_dbg(), scratch.dR_dbg());
  EXPECT_EQ(reintegrated.dV_dba(), scratch.dV_dba());
  EXPECT_EQ(reintegrated.dV_dbg(), scratch.dV_dbg());
  EXPECT_EQ(reintegrated.dP_dba(), scratch.dP_dba());
  EXPECT_EQ(reintegrated.dP_dbg(), scratch.dP_dbg());
  EXPECT_FALSE(reintegrated.needsReintegration(kTrueBias, 0.1, 0.001));
}

// ---------------------------------------------------------------------------------------------
// Covariance (eq. 62-63).

TEST(ImuPreintegration, CovarianceIsSymmetricPositiveDefiniteAndGrows) {
  const sim::ContinuousTrajectory drive = carDrive();
  const std::vector<ImuSample> imu = driveImu(drive);
  ImuPreintegration pre(ImuBias{}, ImuNoise{});
  double previous_trace = 0.0;
  ImuPreintegration::Matrix9d previous = ImuPreintegration::Matrix9d::Zero();
  for (std::size_t k = 200; k < 500; ++k) {
    pre.integrate(imu[k], imu[k + 1]);
    const ImuPreintegration::Matrix9d& P = pre.covariance();
    ASSERT_EQ(P, P.transpose());
    ASSERT_GT(P.trace(), previous_trace);
    previous_trace = P.trace();
    if (k % 100 == 99) {  // every second: PD, and every variance larger than a second ago
      const Eigen::SelfAdjointEigenSolver<ImuPreintegration::Matrix9d> eig(P);
      EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
      EXPECT_TRUE((P.diagonal().array() > previous.diagonal().array()).all());
      previous = P;
    }
  }
}

// A stationary level IMU: gyro white noise of density n integrated over T gives the rotation
// variance n^2 T; the vertical velocity and position see only the accelerometer (n_a^2 T and
// n_a^2 T^3 / 3); horizontal velocity adds gravity times the tilt error (g^2 n_g^2 T^3 / 3).
TEST(ImuPreintegration, StationaryCovarianceMatchesWhiteNoiseTheory) {
  const ImuNoise noise;
  ImuPreintegration pre(ImuBias{}, noise);
  const Eigen::Vector3d specific_force(0.0, 0.0, kGravity_mps2);
  for (int k = 0; k < 1000; ++k) pre.integrate(0.01, specific_force, Eigen::Vector3d::Zero());
  const double T = pre.deltaT(), g = kGravity_mps2;
  const double ng2 = noise.gyr_noise_density * noise.gyr_noise_density;
  const double na2 = noise.acc_noise_density * noise.acc_noise_density;
  const ImuPreintegration::Matrix9d& P = pre.covariance();
  using I = ImuPreintegration;

  const Eigen::Matrix3d rot = P.block<3, 3>(I::kRowR, I::kRowR);
  EXPECT_LT(relativeError(rot, ng2 * T * Eigen::Matrix3d::Identity()), 0.1);
  EXPECT_NEAR(P(I::kRowV + 2, I::kRowV + 2) / (na2 * T), 1.0, 0.1);
  EXPECT_NEAR(P(I::kRowP + 2, I::kRowP + 2) / (na2 * T * T * T / 3.0), 1.0, 0.1);
  const double horizontal_v = na2 * T + g * g * ng2 * T * T * T / 3.0;
  EXPECT_NEAR(P(I::kRowV, I::kRowV) / horizontal_v, 1.0, 0.1);
  EXPECT_NEAR(P(I::kRowV + 1, I::kRowV + 1) / horizontal_v, 1.0, 0.1);

  const Eigen::Matrix<double, 6, 6> bias_cov = pre.biasRandomWalkCovariance();
  EXPECT_NEAR(bias_cov(0, 0), noise.acc_random_walk * noise.acc_random_walk * T, 1e-18);
  EXPECT_NEAR(bias_cov(5, 5), noise.gyr_random_walk * noise.gyr_random_walk * T, 1e-18);

  recordValue("rotation_variance_ratio", rot(0, 0) / (ng2 * T));
  recordValue("vertical_velocity_variance_ratio", P(I::kRowV + 2, I::kRowV + 2) / (na2 * T));
  recordValue("vertical_position_variance_ratio",
              P(I::kRowP + 2, I::kRowP + 2) / (na2 * T * T * T / 3.0));
  recordValue("horizontal_velocity_variance_ratio", P(I::kRowV, I::kRowV) / horizontal_v);
}

// ---------------------------------------------------------------------------------------------
// Bad input.

TEST(ImuPreintegration, RejectsBadInput) {
  ImuPreintegration pre(ImuBias{}, ImuNoise{});
  const Eigen::Vector3d acc(0.0, 0.0, kGravity_mps2), gyr = Eigen::Vector3d::Zero();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(pre.integrate(0.0, acc, gyr), InvalidInput);
  EXPECT_THROW(pre.integrate(-0.01, acc, gyr), InvalidInput);
  EXPECT_THROW(pre.integrate(nan, acc, gyr), InvalidInput);
  EXPECT_THROW(pre.integrate(0.01, Eigen::Vector3d(nan, 0.0, 0.0), gyr), InvalidInput);

  ImuSample a, b;
  a.t_ns = 1000;
  b.t_ns = 1000;
  EXPECT_THROW(pre.integrate(a, b), InvalidInput);
  b.t_ns = 999;
  EXPECT_THROW(pre.integrate(a, b), InvalidInput);
  EXPECT_EQ(pre.intervalCount(), 0u);
  EXPECT_EQ(pre.deltaT(), 0.0);

  ImuNoise bad_noise;
  bad_noise.gyr_noise_density = 0.0;
  EXPECT_THROW(ImuPreintegration(ImuBias{}, bad_noise), InvalidInput);
  ImuBias bad_bias;
  bad_bias.gyr.x() = nan;
  EXPECT_THROW(ImuPreintegration(bad_bias, ImuNoise{}), InvalidInput);
  EXPECT_THROW(pre.reintegrate(bad_bias), InvalidInput);
}

}  // namespace
}  // namespace gvio::odometry
