// The camera-IMU time offset is held where the window's motion cannot observe it (Li and Mourikis
// 2014): constant body-frame angular rate and specific force. The excitation is read from the
// window frames' IMU preintegrations alone.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>

#include "odometry/error.hpp"
#include "odometry/fixed_block_cost.hpp"
#include "odometry/sliding_window.hpp"
#include "odometry/time_offset_factor.hpp"

namespace gvio::odometry {
namespace {

constexpr double kStep = 0.01;      // 100 Hz IMU
constexpr int kStepsPerFrame = 10;  // 10 Hz camera
constexpr int kFrames = 11;

using Signal = std::function<Eigen::Vector3d(double t_s)>;

// A window of kFrames frames whose preintegrations integrate acc_b(t) and gyr_b(t).
void fill(SlidingWindow& window, const Signal& acc_b, const Signal& gyr_b) {
  for (int k = 0; k < kFrames; ++k) {
    auto f = std::make_unique<WindowFrame>();
    f->uid = static_cast<std::uint64_t>(k + 1);
    f->t_ns = static_cast<std::int64_t>(k) * kStepsPerFrame * 10'000'000;
    if (k > 0) {
      f->preintegration = std::make_shared<ImuPreintegration>(ImuBias{}, ImuNoise{});
      for (int i = 0; i < kStepsPerFrame; ++i) {
        const double t_s = ((k - 1) * kStepsPerFrame + i) * kStep;
        f->preintegration->integrate(kStep, acc_b(t_s), gyr_b(t_s));
      }
    }
    window.frames().push_back(std::move(f));
  }
}

Signal constant(const Eigen::Vector3d& v) {
  return [v](double) { return v; };
}

TEST(TimeOffsetHold, ASteadyTurnIsStationaryAndHoldsIt) {
  SlidingWindow window(EstimatorConfig{}, StereoGeometry{});
  // 8 m/s around a 26.7 m radius: 0.3 rad/s, 2.4 m/s^2 towards the centre, gravity's reaction.
  fill(window, constant({0.0, 2.4, 9.81}), constant({0.0, 0.0, 0.3}));
  const TimeOffsetExcitation e = window.timeOffsetExcitation();
  EXPECT_LT(e.rate_change_radps, 1e-9);
  EXPECT_LT(e.force_change_mps2, 1e-9);
  EXPECT_TRUE(window.timeOffsetUnobservable());
}

TEST(TimeOffsetHold, ASlalomChangesTheRateAndFreesIt) {
  SlidingWindow window(EstimatorConfig{}, StereoGeometry{});
  const double w = 2.0 * std::numbers::pi * 0.4;
  fill(window, constant({0.0, 0.0, 9.81}),
       [w](double t) { return Eigen::Vector3d(0.0, 0.0, 0.5 * std::sin(w * t)); });
  const TimeOffsetExcitation e = window.timeOffsetExcitation();
  // Over one second the rate sweeps 0 -> 0.5 -> 0.3 rad/s: the largest deviation from the mean.
  EXPECT_GT(e.rate_change_radps, 0.2);
  EXPECT_LT(e.rate_change_radps, 0.5);
  EXPECT_FALSE(window.timeOffsetUnobservable());
}

TEST(TimeOffsetHold, BrakingOnAStraightChangesTheForceAndFreesIt) {
  SlidingWindow window(EstimatorConfig{}, StereoGeometry{});
  // Cruising, then braking at 3 m/s^2 from the middle of the window: no rotation at all.
  fill(
      window, [](double t) { return Eigen::Vector3d(t < 0.5 ? 0.0 : -3.0, 0.0, 9.81); },
      constant(Eigen::Vector3d::Zero()));
  const TimeOffsetExcitation e = window.timeOffsetExcitation();
  EXPECT_LT(e.rate_change_radps, 1e-12);
  EXPECT_NEAR(e.force_change_mps2, 1.5, 1e-9);  // five intervals at 0, five at -3 m/s^2
  EXPECT_FALSE(window.timeOffsetUnobservable());
}

TEST(TimeOffsetHold, SmallChangesBelowBothThresholdsHoldIt) {
  SlidingWindow window(EstimatorConfig{}, StereoGeometry{});
  // A straight with a slight sway: 0.004 rad/s and 0.08 m/s^2 of change at most.
  fill(
      window, [](double t) { return Eigen::Vector3d(0.08 * std::sin(3.0 * t), 0.0, 9.81); },
      [](double t) { return Eigen::Vector3d(0.0, 0.0, 0.004 * std::sin(3.0 * t)); });
  const TimeOffsetExcitation e = window.timeOffsetExcitation();
  EXPECT_GT(e.rate_change_radps, 0.001);
  EXPECT_GT(e.force_change_mps2, 0.02);
  EXPECT_TRUE(window.timeOffsetUnobservable());
}

TEST(TimeOffsetHold, ZeroThresholdsNeverHoldIt) {
  EstimatorConfig config;
  config.time_offset_min_rate_change_radps = 0.0;
  config.time_offset_min_force_change_mps2 = 0.0;
  SlidingWindow window(config, StereoGeometry{});
  fill(window, constant({0.0, 0.0, 9.81}), constant(Eigen::Vector3d::Zero()));
  EXPECT_FALSE(window.timeOffsetUnobservable());
}

TEST(TimeOffsetHold, NegativeThresholdsAreRefused) {
  EstimatorConfig config;
  config.time_offset_min_rate_change_radps = -0.1;
  EXPECT_THROW(config.validate(), InvalidInput);
  config = EstimatorConfig{};
  config.time_offset_min_force_change_mps2 = std::nan("");
  EXPECT_THROW(config.validate(), InvalidInput);
  config = EstimatorConfig{};
  config.time_offset_hold_median_solves = 0;  // a hold needs at least one free solve's value
  EXPECT_THROW(config.validate(), InvalidInput);
}

// The marginalisation folds a held t_d's residuals in through FixedBlockCost: the same residuals
// and Jacobians of the other blocks as the factor itself, with t_d no longer a block.
TEST(TimeOffsetHold, AFixedBlockCostIsTheFactorWithoutItsBlock) {
  PinholeView camera{700.0, 700.0, 600.0, 180.0, Eigen::Isometry3d::Identity()};
  const MovingPixel anchor{{650.0, 170.0}, {40.0, -5.0}};
  const MovingPixel observed{{655.0, 171.0}, {42.0, -4.0}};
  auto inner =
      std::make_shared<ReprojectionTimeOffsetFactor>(anchor, camera, camera, observed, 1.0);
  std::array<double, 7> pose_i{0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0};
  std::array<double, 7> pose_j{0.2, 0.0, 1.0, 0.0, 0.01, 0.0, 1.0};
  double rho = 0.05;
  double t_d = 0.012;
  const double* inner_params[] = {pose_i.data(), pose_j.data(), &rho, &t_d};
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> Ji, Jj;
  Eigen::Vector2d Jr, Jt, r_inner;
  double* inner_jac[] = {Ji.data(), Jj.data(), Jr.data(), Jt.data()};
  ASSERT_TRUE(inner->Evaluate(inner_params, r_inner.data(), inner_jac));

  const FixedBlockCost held(inner, 3, {t_d});
  ASSERT_EQ(held.parameter_block_sizes(), (std::vector<int>{7, 7, 1}));
  EXPECT_EQ(held.num_residuals(), 2);
  const double* params[] = {pose_i.data(), pose_j.data(), &rho};
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> Hi, Hj;
  Eigen::Vector2d Hr, r;
  double* jac[] = {Hi.data(), Hj.data(), Hr.data()};
  ASSERT_TRUE(held.Evaluate(params, r.data(), jac));
  EXPECT_EQ(r, r_inner);
  EXPECT_EQ(Hi, Ji);
  EXPECT_EQ(Hj, Jj);
  EXPECT_EQ(Hr, Jr);
  // The held value is the one given, not whatever the caller's t_d becomes afterwards.
  t_d = 0.0;
  ASSERT_TRUE(held.Evaluate(params, r.data(), nullptr));
  EXPECT_EQ(r, r_inner);
  EXPECT_THROW(FixedBlockCost(inner, 4, {0.0}), InvalidInput);
  EXPECT_THROW(FixedBlockCost(inner, 3, {0.0, 1.0}), InvalidInput);
  EXPECT_THROW(FixedBlockCost(nullptr, 0, {}), InvalidInput);
}

}  // namespace
}  // namespace gvio::odometry
