// The camera-IMU time offset inside the visual-inertial initialisation: exact synthetic windows
// whose visual poses belong to exposures t_d before the stamps the IMU is preintegrated between.
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "odometry/lie.hpp"
#include "odometry/vi_alignment.hpp"

namespace gvio::odometry {
namespace {

constexpr double kStep = 0.005;  // IMU period (s)
constexpr int kStepsPerFrame = 20;
constexpr int kFrames = 13;
constexpr int kLeadSteps = 40;  // simulated before the first stamp, so a lagged pose exists
constexpr int kTrailSteps = 4;  // and after the last one, for the numeric derivative

struct State {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
};

// A slalom (yaw rate 1 rad/s at 0.4 Hz, a little roll and pitch) or, with `slalom` false, a
// steady turn at a constant rate: the time offset is observable in the first only.
Eigen::Vector3d bodyRate(double t, bool slalom) {
  if (!slalom) return {0.0, 0.0, 0.3};
  const double w = 2.0 * std::numbers::pi * 0.4;
  return {0.05 * std::sin(1.3 * t), 0.03 * std::cos(0.9 * t), 1.0 * std::sin(w * t)};
}

struct Window {
  std::vector<AlignmentFrame> frames;
  std::vector<Eigen::Vector3d> v_v;     // true velocity at each stamp
  std::vector<Eigen::Vector3d> rate_b;  // true body rate at each stamp
  std::vector<State> states;            // every IMU step, from -kLeadSteps
};

// Frames every 0.1 s; frame k's stamp is step kLeadSteps + 20 k, its visual pose the state
// `lag_steps` steps earlier. The truth is propagated with the preintegration's own discrete model
// (constant measurement per step), so the only model error left is the time offset's.
Window makeWindow(int lag_steps, const Eigen::Vector3d& gyr_bias, bool slalom) {
  const Eigen::Vector3d g_w(0, 0, -kGravity_mps2);
  Window w;
  State s;
  s.v = Eigen::Vector3d(6.0, 0.0, 0.0);
  const int total = kLeadSteps + kStepsPerFrame * (kFrames - 1) + kTrailSteps;
  std::vector<Eigen::Vector3d> omega(total), acc(total);
  for (int i = 0; i < total; ++i) {
    w.states.push_back(s);
    const double t = (i - kLeadSteps + 0.5) * kStep;
    omega[i] = bodyRate(t, slalom);
    const Eigen::Vector3d a_b(0.5 * std::sin(2.0 * t), 0.4 * std::cos(1.7 * t), 0.05);
    acc[i] = a_b - s.R.transpose() * g_w;  // specific force
    const Eigen::Vector3d a_w = s.R * acc[i] + g_w;
    s.p += s.v * kStep + 0.5 * a_w * kStep * kStep;
    s.v += a_w * kStep;
    s.R = normalizeRotation(s.R * expSo3(omega[i] * kStep));
  }
  w.states.push_back(s);
  for (int k = 0; k < kFrames; ++k) {
    const int stamp = kLeadSteps + kStepsPerFrame * k;
    AlignmentFrame f;
    f.R_v_b = w.states[stamp - lag_steps].R;
    f.p_v_b = w.states[stamp - lag_steps].p;
    if (k > 0) {
      auto pre = std::make_shared<ImuPreintegration>(ImuBias{}, ImuNoise{});
      for (int i = stamp - kStepsPerFrame; i < stamp; ++i) {
        pre->integrate(kStep, acc[i], omega[i] + gyr_bias);
      }
      f.preintegration = pre;
    }
    w.frames.push_back(f);
    w.v_v.push_back(w.states[stamp].v);
    w.rate_b.push_back(bodyRate((stamp - kLeadSteps) * kStep, slalom));
  }
  return w;
}

TEST(ViAlignmentTimeOffset, StampRatesFollowTheGyroscope) {
  const Window w = makeWindow(0, Eigen::Vector3d::Zero(), true);
  const std::vector<Eigen::Vector3d> rates = stampRates(w.frames);
  ASSERT_EQ(rates.size(), w.frames.size());
  for (std::size_t k = 0; k < rates.size(); ++k) {
    // Second order in the frame period inside, first order at the extrapolated ends.
    const double tolerance = (k == 0 || k + 1 == rates.size()) ? 0.05 : 0.015;
    EXPECT_LT((rates[k] - w.rate_b[k]).norm(), tolerance) << "frame " << k;
  }
}

TEST(ViAlignmentTimeOffset, ItsColumnIsTheDerivativeOfTheRotationResidual) {
  // d/dt_d Log(dR_ij^T R_i(t - t_d)^T R_j(t - t_d)) at t_d = 0 against central differences of
  // the simulated poses one IMU step either side.
  const Window w = makeWindow(0, Eigen::Vector3d::Zero(), true);
  for (int k = 1; k < kFrames; ++k) {
    const int sj = kLeadSteps + kStepsPerFrame * k, si = sj - kStepsPerFrame;
    const Eigen::Matrix3d dR = w.frames[static_cast<std::size_t>(k)].preintegration->deltaR();
    auto residual = [&](int lag) {
      const Eigen::Matrix3d R_ij = w.states[si - lag].R.transpose() * w.states[sj - lag].R;
      return Eigen::Vector3d(logSo3(dR.transpose() * R_ij));
    };
    const Eigen::Vector3d numeric = (residual(1) - residual(-1)) / (2.0 * kStep);
    const Eigen::Vector3d analytic =
        dR.transpose() * w.rate_b[static_cast<std::size_t>(k) - 1] - w.rate_b[k];
    EXPECT_LT((numeric - analytic).norm(), 0.02 * std::max(1.0, analytic.norm()))
        << "interval " << k << ": numeric " << numeric.transpose() << " analytic "
        << analytic.transpose();
  }
}

TEST(ViAlignmentTimeOffset, RecoversALagOfTwentyMillisecondsWithTheBias) {
  const Eigen::Vector3d gyr_bias(0.004, -0.006, 0.008);
  const Window w = makeWindow(4, gyr_bias, true);  // stamps 20 ms late
  const GyroBiasTimeOffset solved = solveGyroBiasAndTimeOffset(w.frames, {0.0, 0.05});
  EXPECT_TRUE(solved.observed);
  EXPECT_NEAR(solved.t_d_s, 0.020, 1e-3);
  EXPECT_LT(solved.t_d_sigma_s, 2e-3);
  const double joint_error = (solved.gyr_bias - gyr_bias).norm();
  // Without the offset the bias absorbs the lag.
  const double alone_error = (solveGyroBias(w.frames) - gyr_bias).norm();
  std::printf("gyro bias error: %.2f mrad/s with the offset, %.2f mrad/s without\n",
              1e3 * joint_error, 1e3 * alone_error);
  EXPECT_LT(joint_error, 1e-3);  // second-order terms of the 20 ms lag
  EXPECT_GT(alone_error, 3.0 * joint_error);
}

TEST(ViAlignmentTimeOffset, ASteadyTurnLeavesItAtThePrior) {
  // At a constant rate a lag only rotates every pose by the same amount: nothing to estimate.
  const Eigen::Vector3d gyr_bias(0.004, -0.006, 0.008);
  const Window w = makeWindow(4, gyr_bias, false);
  const GyroBiasTimeOffset solved = solveGyroBiasAndTimeOffset(w.frames, {0.003, 0.05});
  EXPECT_FALSE(solved.observed);
  EXPECT_EQ(solved.t_d_s, 0.003);
  EXPECT_GT(solved.t_d_sigma_s, 0.02);
  EXPECT_EQ(solved.gyr_bias, solveGyroBias(w.frames));
}

TEST(ViAlignmentTimeOffset, TheAlignmentUsesItForVelocities) {
  const Eigen::Vector3d gyr_bias(0.004, -0.006, 0.008);
  Window with = makeWindow(4, gyr_bias, true);
  const auto result = alignVisualInertial(with.frames, false, 0.1, 0.05, TimeOffsetPrior{});
  ASSERT_TRUE(result.has_value());
  EXPECT_TRUE(result->t_d_observed);
  EXPECT_NEAR(result->t_d_s, 0.020, 1e-3);
  Window without = makeWindow(4, gyr_bias, true);
  const auto plain = alignVisualInertial(without.frames, false);
  ASSERT_TRUE(plain.has_value());
  EXPECT_EQ(plain->t_d_s, 0.0);
  double err_with = 0.0, err_plain = 0.0;
  for (std::size_t k = 0; k < with.v_v.size(); ++k) {
    err_with += (result->v_v[k] - with.v_v[k]).norm();
    err_plain += (plain->v_v[k] - without.v_v[k]).norm();
  }
  EXPECT_LT(err_with / static_cast<double>(with.v_v.size()), 0.02);
  EXPECT_LT(err_with, 0.5 * err_plain);
}

}  // namespace
}  // namespace gvio::odometry
