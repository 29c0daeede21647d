#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

Eigen::Matrix3d rotationZyx(double roll, double pitch, double yaw) {
  return odometry::rotationZyx({roll, pitch, yaw});
}

// A car-like drive: 20 m/s along x, a 30 m lateral weave, a gentle climb; yaw follows the heading,
// roll and pitch sway a little.
struct CarTruth {
  static Eigen::Vector3d p(double t) {
    return {20.0 * t, 30.0 * std::sin(0.1 * t), 0.5 * std::sin(0.05 * t)};
  }
  static Eigen::Vector3d v(double t) {
    return {20.0, 3.0 * std::cos(0.1 * t), 0.025 * std::cos(0.05 * t)};
  }
  static Eigen::Vector3d a(double t) {
    return {0.0, -0.3 * std::sin(0.1 * t), -0.00125 * std::sin(0.05 * t)};
  }
  static Eigen::Matrix3d R(double t) {
    return rotationZyx(0.02 * std::sin(0.3 * t), 0.01 * std::sin(0.2 * t),
                       std::atan2(3.0 * std::cos(0.1 * t), 20.0));
  }
};

constexpr std::int64_t kT0Ns = 1'000'000'000'000;  // an arbitrary non-zero start

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns - kT0Ns) * 1e-9;
}

template <typename Truth>
Trajectory sampled(double duration_s, double rate_hz) {
  Trajectory traj;
  const auto n = static_cast<int>(std::lround(duration_s * rate_hz));
  for (int i = 0; i <= n; ++i) {
    const std::int64_t t_ns = kT0Ns + std::llround(i * 1e9 / rate_hz);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Truth::R(seconds(t_ns));
    T.translation() = Truth::p(seconds(t_ns));
    traj.t_ns.push_back(t_ns);
    traj.poses.push_back(T);
  }
  return traj;
}

// Body rate by a central difference of R: log(R(t - h)^T R(t + h)) / (2 h).
template <typename RotationAt>
Eigen::Vector3d numericRate(RotationAt rotation_at, std::int64_t t_ns, std::int64_t h_ns) {
  const Eigen::AngleAxisd delta(rotation_at(t_ns - h_ns).transpose() * rotation_at(t_ns + h_ns));
  return delta.angle() * delta.axis() / (2.0 * static_cast<double>(h_ns) * 1e-9);
}

std::vector<std::int64_t> randomStamps(std::int64_t from_ns, std::int64_t to_ns, int count) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> pick(from_ns, to_ns);
  std::vector<std::int64_t> stamps(static_cast<std::size_t>(count));
  for (auto& t : stamps) t = pick(rng);
  return stamps;
}

TEST(SimTrajectoryFit, ReproducesAnalyticCarDrive) {
  const auto fitted = ContinuousTrajectory::fit(sampled<CarTruth>(60.0, 10.0));
  EXPECT_EQ(fitted.report().poses, 601u);
  EXPECT_LT(fitted.report().position_rms_m, 0.01);
  EXPECT_LT(fitted.report().rotation_rms_deg, 0.05);
  EXPECT_EQ(fitted.t0_ns(), kT0Ns);
  EXPECT_EQ(fitted.t1_ns(), kT0Ns + 60'000'000'000);

  // Away from the ends, where the splines have data on both sides.
  for (const std::int64_t t_ns : randomStamps(kT0Ns + 2'000'000'000, kT0Ns + 58'000'000'000, 200)) {
    const BodyState s = fitted.at(t_ns);
    const double t = seconds(t_ns);
    EXPECT_LT((s.p_w - CarTruth::p(t)).norm(), 0.01) << "t = " << t;
    EXPECT_LT((s.v_w - CarTruth::v(t)).norm(), 0.02) << "t = " << t;
    EXPECT_LT((s.a_w - CarTruth::a(t)).norm(), 0.1) << "t = " << t;
    const double rot_err_deg =
        Eigen::AngleAxisd(s.R_w_b.transpose() * CarTruth::R(t)).angle() * kDeg;
    EXPECT_LT(rot_err_deg, 0.05) << "t = " << t;
    const Eigen::Vector3d true_rate =
        numericRate([](std::int64_t u) { return CarTruth::R(seconds(u)); }, t_ns, 1'000'000);
    EXPECT_LT((s.omega_b - true_rate).norm(), 1e-3) << "t = " << t;
    // omega_b also agrees with the fitted rotation's own numeric derivative.
    const Eigen::Vector3d fitted_rate =
        numericRate([&](std::int64_t u) { return fitted.at(u).R_w_b; }, t_ns, 100'000);
    EXPECT_LT((s.omega_b - fitted_rate).norm(), 1e-6) << "t = " << t;
  }
}

TEST(SimTrajectoryFit, PureLeastSquaresAlsoFits) {
  const auto fitted = ContinuousTrajectory::fit(sampled<CarTruth>(60.0, 10.0),
                                                {.knot_spacing_s = 0.25, .smoothing = 0.0});
  EXPECT_LT(fitted.report().position_rms_m, 0.01);
  EXPECT_LT(fitted.report().rotation_rms_deg, 0.05);
}

TEST(SimTrajectoryFit, DerivativesMatchCentralDifferences) {
  const auto fitted = ContinuousTrajectory::fit(sampled<CarTruth>(60.0, 10.0));
  constexpr std::int64_t kH = 100'000;  // 0.1 ms
  constexpr double kHs = 1e-4;
  for (const std::int64_t t_ns : randomStamps(kT0Ns + 1'000'000, kT0Ns + 59'999'000'000, 200)) {
    const BodyState lo = fitted.at(t_ns - kH), mid = fitted.at(t_ns), hi = fitted.at(t_ns + kH);
    const Eigen::Vector3d v_num = (hi.p_w - lo.p_w) / (2.0 * kHs);
    const Eigen::Vector3d a_num = (hi.v_w - lo.v_w) / (2.0 * kHs);
    EXPECT_LT((v_num - mid.v_w).norm(), 1e-4 * mid.v_w.norm()) << "t_ns = " << t_ns;
    EXPECT_LT((a_num - mid.a_w).norm(), 1e-4 * mid.a_w.norm()) << "t_ns = " << t_ns;
  }
}

TEST(SimTrajectoryFit, ClampsToTheFittedInterval) {
  const auto fitted = ContinuousTrajectory::fit(sampled<CarTruth>(10.0, 10.0));
  const BodyState first = fitted.at(fitted.t0_ns()), before = fitted.at(fitted.t0_ns() - 5'000);
  const BodyState last = fitted.at(fitted.t1_ns()), after = fitted.at(fitted.t1_ns() + 5'000);
  EXPECT_EQ(first.p_w, before.p_w);
  EXPECT_EQ(last.p_w, after.p_w);
  EXPECT_LT((first.p_w - CarTruth::p(0.0)).norm(), 0.01);
  EXPECT_LT((last.p_w - CarTruth::p(10.0)).norm(), 0.01);
  EXPECT_TRUE(last.v_w.allFinite() && last.a_w.allFinite() && last.omega_b.allFinite());
  const Eigen::Isometry3d T = last.pose();
  EXPECT_EQ(T.translation(), last.p_w);
  EXPECT_EQ(T.linear(), last.R_w_b);
  EXPECT_THROW((void)ContinuousTrajectory().at(0), std::logic_error);
}

// Three laps of a 50 m circle in 60 s: the yaw passes +-pi six times.
struct CircleTruth {
  static constexpr double kRate = 3.0 * 2.0 * std::numbers::pi / 60.0;
  static Eigen::Vector3d p(double t) {
    return {50.0 * std::cos(kRate * t), 50.0 * std::sin(kRate * t), 0.0};
  }
  static Eigen::Matrix3d R(double t) {
    return rotationZyx(0.01 * std::sin(t), 0.0, kRate * t + std::numbers::pi / 2.0);
  }
};

TEST(SimTrajectoryFit, UnwrapsYawAcrossPi) {
  const auto fitted = ContinuousTrajectory::fit(sampled<CircleTruth>(60.0, 10.0));
  EXPECT_LT(fitted.report().rotation_rms_deg, 0.05);
  EXPECT_LT(fitted.report().rotation_max_deg, 0.1);
  EXPECT_LT(fitted.report().position_rms_m, 0.01);
  for (const std::int64_t t_ns : randomStamps(kT0Ns + 1'000'000'000, kT0Ns + 59'000'000'000, 300)) {
    EXPECT_NEAR(fitted.at(t_ns).omega_b.z(), CircleTruth::kRate, 1e-3) << "t_ns = " << t_ns;
  }
}

TEST(SimTrajectoryFit, RejectsBadInput) {
  Trajectory three = sampled<CarTruth>(0.2, 10.0);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_THROW((void)ContinuousTrajectory::fit(three), InvalidInput);

  Trajectory unstamped = sampled<CarTruth>(1.0, 10.0);
  unstamped.t_ns.clear();
  EXPECT_THROW((void)ContinuousTrajectory::fit(unstamped), InvalidInput);

  Trajectory repeated = sampled<CarTruth>(1.0, 10.0);
  repeated.t_ns[5] = repeated.t_ns[4];
  EXPECT_THROW((void)ContinuousTrajectory::fit(repeated), InvalidInput);

  // Without smoothing, a 5 s gap leaves control points no pose constrains.
  Trajectory gap = sampled<CarTruth>(1.0, 10.0);
  for (std::size_t i = 6; i < gap.size(); ++i) gap.t_ns[i] += 5'000'000'000;
  EXPECT_THROW((void)ContinuousTrajectory::fit(gap, {.knot_spacing_s = 0.25, .smoothing = 0.0}),
               InvalidInput);
  EXPECT_NO_THROW((void)ContinuousTrajectory::fit(gap));

  Trajectory steep = sampled<CarTruth>(1.0, 10.0);
  steep.poses[3].linear() = rotationZyx(0.0, 85.0 / kDeg, 0.0);
  EXPECT_THROW((void)ContinuousTrajectory::fit(steep), InvalidInput);
}

// KITTI odometry ground truth: one 3x4 row-major T_w_c per line, times in seconds.
Trajectory readKittiBodyPoses(const std::filesystem::path& poses_file,
                              const std::filesystem::path& times_file) {
  // Body x forward / y left / z up in the camera's x right / y down / z forward.
  Eigen::Matrix3d R_c_b;
  R_c_b << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  // Camera world (x right, y down, z forward) to ENU-like (x, z -> y, -y -> z).
  Eigen::Matrix3d R_enu_w;
  R_enu_w << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  Trajectory traj;
  std::ifstream poses(poses_file), times(times_file);
  Eigen::Matrix<double, 3, 4> T_w_c;
  double t_s = 0.0;
  while (times >> t_s) {
    for (int i = 0; i < 12; ++i) poses >> T_w_c(i / 4, i % 4);
    if (!poses) break;
    Eigen::Isometry3d T_enu_b = Eigen::Isometry3d::Identity();
    T_enu_b.linear() = R_enu_w * T_w_c.leftCols<3>() * R_c_b;
    T_enu_b.translation() = R_enu_w * T_w_c.col(3);
    traj.t_ns.push_back(std::llround(t_s * 1e9));
    traj.poses.push_back(T_enu_b);
  }
  return traj;
}

TEST(SimTrajectoryFit, FitsKitti00GroundTruth) {
  const std::filesystem::path dir = std::filesystem::path(GVIO_SHARED_DATA_DIR) / "kitti00";
  const auto poses_file = dir / "KITTI_00_gt.txt", times_file = dir / "KITTI_00_gt_times.txt";
  if (!std::filesystem::exists(poses_file) || !std::filesystem::exists(times_file)) {
    GTEST_SKIP() << "shared data absent: " << dir;
  }
  const Trajectory traj = readKittiBodyPoses(poses_file, times_file);
  ASSERT_EQ(traj.size(), 4541u);

  const auto start = std::chrono::steady_clock::now();
  const auto fitted = ContinuousTrajectory::fit(traj);
  const double fit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const FitReport& r = fitted.report();
  std::cout << "KITTI-00 fit: " << r.poses << " poses in " << fit_ms << " ms; position rms/max "
            << r.position_rms_m << " / " << r.position_max_m << " m; rotation rms/max "
            << r.rotation_rms_deg << " / " << r.rotation_max_deg << " deg\n";
  EXPECT_LT(r.position_rms_m, 0.1);
  EXPECT_LT(r.rotation_rms_deg, 0.5);
  EXPECT_LT(fit_ms, 1000.0);
}

}  // namespace
}  // namespace gvio::sim
