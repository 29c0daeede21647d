#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>

#include "odometry/error.hpp"
#include "sim/imu_synth.hpp"

namespace gvio::sim {
namespace {

constexpr std::int64_t kT0Ns = 500'000'000'000;  // an arbitrary non-zero start

// Poses at 10 Hz over [0, duration] of a trajectory given as p(t) and R(t).
template <typename PositionAt, typename RotationAt>
Trajectory sampled(double duration_s, PositionAt p, RotationAt R) {
  Trajectory traj;
  for (int i = 0; i <= static_cast<int>(std::lround(duration_s * 10.0)); ++i) {
    const double t = 0.1 * i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R(t);
    T.translation() = p(t);
    traj.t_ns.push_back(kT0Ns + 100'000'000LL * i);
    traj.poses.push_back(T);
  }
  return traj;
}

// The car-like drive of sim_trajectory_test: 20 m/s along x, lateral weave, heading-following yaw.
ContinuousTrajectory carDrive(double duration_s) {
  return ContinuousTrajectory::fit(sampled(
      duration_s,
      [](double t) {
        return Eigen::Vector3d(20.0 * t, 30.0 * std::sin(0.1 * t), 0.5 * std::sin(0.05 * t));
      },
      [](double t) {
        return (Eigen::AngleAxisd(std::atan2(3.0 * std::cos(0.1 * t), 20.0),
                                  Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.01 * std::sin(0.2 * t), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.02 * std::sin(0.3 * t), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
      }));
}

ContinuousTrajectory stationary(double duration_s) {
  return ContinuousTrajectory::fit(sampled(
      duration_s, [](double) { return Eigen::Vector3d(3.0, -2.0, 1.0); },
      [](double) { return Eigen::Matrix3d::Identity().eval(); }));
}

Eigen::Matrix3d expSo3(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

// Strapdown integration of noise-free samples: R by the exp map of the mean rate over each step,
// v by the trapezoid rule, p exactly for acceleration linear over the step.
TEST(SimImu, NoiseFreeImuIntegratesBackToTheTrajectory) {
  const ContinuousTrajectory drive = carDrive(10.0);
  ImuSimOptions options;
  options.add_noise = false;
  const auto samples = synthesizeImu(drive, options, 1);
  ASSERT_EQ(samples.size(), 1001u);

  const BodyState start = drive.at(drive.t0_ns());
  Eigen::Matrix3d R = start.R_w_b;
  Eigen::Vector3d v = start.v_w, p = start.p_w;
  const Eigen::Vector3d g_w(0.0, 0.0, -kGravity_mps2);
  double worst_m = 0.0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
    const ImuSample& now = samples[k].measured;
    const ImuSample& next = samples[k + 1].measured;
    EXPECT_EQ(now.acc_b_mps2, samples[k].truth.acc_b_mps2);
    const double dt = static_cast<double>(next.t_ns - now.t_ns) * 1e-9;
    const Eigen::Matrix3d R_next = R * expSo3(0.5 * (now.gyr_b_radps + next.gyr_b_radps) * dt);
    const Eigen::Vector3d a_now = R * now.acc_b_mps2 + g_w;
    const Eigen::Vector3d a_next = R_next * next.acc_b_mps2 + g_w;
    p += v * dt + (a_now / 3.0 + a_next / 6.0) * dt * dt;
    v += 0.5 * (a_now + a_next) * dt;
    R = R_next;
    worst_m = std::max(worst_m, (p - drive.at(next.t_ns).p_w).norm());
  }
  EXPECT_LT(worst_m, 0.05);
  const BodyState end = drive.at(drive.t1_ns());
  EXPECT_LT((v - end.v_w).norm(), 0.01);
  EXPECT_LT(Eigen::AngleAxisd(R.transpose() * end.R_w_b).angle(), 1e-4);
}

TEST(SimImu, StationaryLevelBodyFeelsOnlyGravity) {
  ImuSimOptions options;
  options.add_noise = false;
  for (const ImuSimSample& s : synthesizeImu(stationary(2.0), options, 1)) {
    EXPECT_LT((s.truth.acc_b_mps2 - Eigen::Vector3d(0.0, 0.0, kGravity_mps2)).norm(), 1e-9);
    EXPECT_LT(s.truth.gyr_b_radps.norm(), 1e-12);
    EXPECT_EQ(s.measured.acc_b_mps2, s.truth.acc_b_mps2);
    EXPECT_EQ(s.acc_bias, Eigen::Vector3d::Zero());
  }
}

double sampleStd(const std::vector<double>& x) {
  double mean = 0.0, sq = 0.0;
  for (const double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (const double v : x) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / static_cast<double>(x.size() - 1));
}

// Discrete white noise has sigma = density * sqrt(rate) (Kalibr IMU noise model).
TEST(SimImu, WhiteNoiseHasTheDiscretisedSigma) {
  ImuSimOptions options;
  options.noise.acc_random_walk = 0.0;
  options.noise.gyr_random_walk = 0.0;
  options.initial_acc_bias = Eigen::Vector3d(0.1, -0.2, 0.05);
  const auto samples = synthesizeImu(stationary(100.0), options, 42);
  ASSERT_EQ(samples.size(), 10001u);
  const double acc_sigma = options.noise.acc_noise_density * std::sqrt(options.rate_hz);
  const double gyr_sigma = options.noise.gyr_noise_density * std::sqrt(options.rate_hz);
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> acc, gyr;
    double acc_mean = 0.0;
    for (const ImuSimSample& s : samples) {
      const double acc_err = s.measured.acc_b_mps2[axis] - s.truth.acc_b_mps2[axis];
      acc.push_back(acc_err);
      acc_mean += acc_err / static_cast<double>(samples.size());
      gyr.push_back(s.measured.gyr_b_radps[axis] - s.truth.gyr_b_radps[axis]);
    }
    EXPECT_NEAR(sampleStd(acc), acc_sigma, 0.05 * acc_sigma) << "axis " << axis;
    EXPECT_NEAR(sampleStd(gyr), gyr_sigma, 0.05 * gyr_sigma) << "axis " << axis;
    EXPECT_NEAR(acc_mean, options.initial_acc_bias[axis], 4.0 * acc_sigma / 100.0);
  }
}

// Bias random walk: after N steps of dt the bias has variance rw^2 * N * dt.
TEST(SimImu, BiasRandomWalkVarianceGrowsLinearly) {
  ImuSimOptions options;
  options.noise.acc_noise_density = 0.0;
  options.noise.gyr_noise_density = 0.0;
  const ContinuousTrajectory still = stationary(10.0);
  const std::size_t steps = 1000;
  const double horizon_s = static_cast<double>(steps) / options.rate_hz;
  double normalised_sq = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const auto samples = synthesizeImu(still, options, seed);
    ASSERT_GT(samples.size(), steps);
    const ImuSimSample& s = samples[steps];
    const Eigen::Vector3d acc = s.acc_bias / (options.noise.acc_random_walk * std::sqrt(horizon_s));
    const Eigen::Vector3d gyr = s.gyr_bias / (options.noise.gyr_random_walk * std::sqrt(horizon_s));
    normalised_sq += acc.squaredNorm() + gyr.squaredNorm();
    count += 6;
    // Without white noise the output error is exactly the bias.
    EXPECT_LT((s.measured.acc_b_mps2 - s.truth.acc_b_mps2 - s.acc_bias).norm(), 1e-12);
  }
  EXPECT_NEAR(normalised_sq / count, 1.0, 0.2);
}

bool bitwiseEqual(const ImuSimSample& a, const ImuSimSample& b) {
  const auto same = [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
    return std::memcmp(x.data(), y.data(), 3 * sizeof(double)) == 0;
  };
  return a.measured.t_ns == b.measured.t_ns && same(a.measured.acc_b_mps2, b.measured.acc_b_mps2) &&
         same(a.measured.gyr_b_radps, b.measured.gyr_b_radps) && same(a.acc_bias, b.acc_bias) &&
         same(a.gyr_bias, b.gyr_bias);
}

TEST(SimImu, DeterministicForASeed) {
  const ContinuousTrajectory drive = carDrive(5.0);
  const ImuSimOptions options;
  const auto first = synthesizeImu(drive, options, 2024);
  const auto again = synthesizeImu(drive, options, 2024);
  const auto other = synthesizeImu(drive, options, 2025);
  ASSERT_EQ(first.size(), again.size());
  ASSERT_EQ(first.size(), other.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(bitwiseEqual(first[k], again[k])) << "sample " << k;
    differing += bitwiseEqual(first[k], other[k]) ? 0 : 1;
  }
  EXPECT_EQ(differing, first.size());
}

TEST(SimImu, StampsAreEvenlySpacedFromT0) {
  ImuSimOptions options;
  options.add_noise = false;
  const ContinuousTrajectory still = stationary(10.0);
  const auto samples = synthesizeImu(still, options, 1);
  ASSERT_EQ(samples.size(), 1001u);
  EXPECT_EQ(samples.front().measured.t_ns, still.t0_ns());
  EXPECT_EQ(samples.back().measured.t_ns, still.t1_ns());
  for (std::size_t k = 1; k < samples.size(); ++k) {
    EXPECT_EQ(samples[k].measured.t_ns - samples[k - 1].measured.t_ns, 10'000'000);
    EXPECT_EQ(samples[k].truth.t_ns, samples[k].measured.t_ns);
  }
  // 300 Hz: the period is not whole nanoseconds, yet stamp k is t0 + round(k / 300 s).
  options.rate_hz = 300.0;
  const auto fast = synthesizeImu(still, options, 1);
  ASSERT_EQ(fast.size(), 3001u);
  EXPECT_EQ(fast[1].measured.t_ns - still.t0_ns(), 3'333'333);
  EXPECT_EQ(fast[2].measured.t_ns - still.t0_ns(), 6'666'667);
  EXPECT_EQ(fast.back().measured.t_ns, still.t1_ns());
}

TEST(SimImu, RejectsBadOptions) {
  const ContinuousTrajectory still = stationary(1.0);
  ImuSimOptions options;
  options.rate_hz = 0.0;
  EXPECT_THROW((void)synthesizeImu(still, options, 1), InvalidInput);
  options.rate_hz = 100.0;
  options.noise.acc_noise_density = -1.0;
  EXPECT_THROW((void)synthesizeImu(still, options, 1), InvalidInput);
}

// Per-drive noise (sim.imu_noise_scale_min/max): each density times its own log-uniform draw.
TEST(SimImu, DrawnNoiseIsReproducibleBySeedAndWithinTheRange) {
  const ImuNoise nominal;
  const ImuNoiseDraw a = drawImuNoise(nominal, 0.5, 4.0, 7), b = drawImuNoise(nominal, 0.5, 4.0, 7);
  EXPECT_EQ(a.scale, b.scale);
  EXPECT_NE(a.scale, drawImuNoise(nominal, 0.5, 4.0, 8).scale);
  EXPECT_EQ(a.noise.acc_noise_density, nominal.acc_noise_density * a.scale[0]);
  EXPECT_EQ(a.noise.gyr_noise_density, nominal.gyr_noise_density * a.scale[1]);
  EXPECT_EQ(a.noise.acc_random_walk, nominal.acc_random_walk * a.scale[2]);
  EXPECT_EQ(a.noise.gyr_random_walk, nominal.gyr_random_walk * a.scale[3]);
  // Log-uniform over many seeds: within the range, log of the scale uniform (mean and spread).
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 0; seed < 2000; ++seed) {
    for (const double scale : drawImuNoise(nominal, 0.5, 4.0, seed).scale) {
      ASSERT_GE(scale, 0.5);
      ASSERT_LE(scale, 4.0);
      const double x = std::log(scale);
      sum += x;
      sum2 += x * x;
      ++n;
    }
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  const double lo = std::log(0.5), hi = std::log(4.0);
  EXPECT_NEAR(mean, (lo + hi) / 2.0, 0.02);
  EXPECT_NEAR(var, (hi - lo) * (hi - lo) / 12.0, 0.02);
}

TEST(SimImu, UnitScaleKeepsTheNominalNoiseExactly) {
  const ImuNoise nominal;
  const ImuNoiseDraw d = drawImuNoise(nominal, 1.0, 1.0, 42);
  EXPECT_EQ(d.scale, (std::array<double, 4>{1.0, 1.0, 1.0, 1.0}));
  EXPECT_EQ(0, std::memcmp(&d.noise, &nominal, sizeof(ImuNoise)));
  EXPECT_THROW((void)drawImuNoise(nominal, 2.0, 1.0, 1), InvalidInput);
  EXPECT_THROW((void)drawImuNoise(nominal, 0.0, 1.0, 1), InvalidInput);
}

// Per-drive turn-on biases (sim.imu_turn_on_*): N(0, sigma^2) per axis by seed, none at sigma 0.
TEST(SimImu, TurnOnBiasIsReproducibleBySeedWithTheStatedSigma) {
  const TurnOnBias a = drawTurnOnBias(0.1, 0.002, 3), b = drawTurnOnBias(0.1, 0.002, 3);
  EXPECT_EQ(a.acc_mps2, b.acc_mps2);
  EXPECT_EQ(a.gyr_radps, b.gyr_radps);
  EXPECT_NE(a.acc_mps2, drawTurnOnBias(0.1, 0.002, 4).acc_mps2);
  // One sigma does not change the other's draw.
  EXPECT_EQ(drawTurnOnBias(0.0, 0.002, 3).gyr_radps, a.gyr_radps);
  const TurnOnBias none = drawTurnOnBias(0.0, 0.0, 3);
  EXPECT_EQ(none.acc_mps2, Eigen::Vector3d::Zero());
  EXPECT_EQ(none.gyr_radps, Eigen::Vector3d::Zero());
  double acc2 = 0.0, gyr2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 0; seed < 2000; ++seed) {
    const TurnOnBias d = drawTurnOnBias(0.1, 0.002, seed);
    acc2 += d.acc_mps2.squaredNorm();
    gyr2 += d.gyr_radps.squaredNorm();
    n += 3;
  }
  EXPECT_NEAR(std::sqrt(acc2 / n), 0.1, 0.004);  // 6000 draws: the sample sigma within ~4 %
  EXPECT_NEAR(std::sqrt(gyr2 / n), 0.002, 0.00008);
  EXPECT_THROW((void)drawTurnOnBias(-0.1, 0.0, 1), InvalidInput);
  EXPECT_THROW((void)drawTurnOnBias(0.0, std::nan(""), 1), InvalidInput);
}

// The drawn bias is where the bias walk starts: in the first sample exactly, and in the mean
// error of the measurements within the white noise (2 s at 100 Hz: acc ~0.0014 m/s^2, gyr ~1e-4
// rad/s).
TEST(SimImu, TurnOnBiasIsInTheMeasurements) {
  const ContinuousTrajectory drive = carDrive(2.0);
  ImuSimOptions options;
  const TurnOnBias bias = drawTurnOnBias(0.2, 0.01, 9);
  options.initial_acc_bias = bias.acc_mps2;
  options.initial_gyr_bias = bias.gyr_radps;
  const auto samples = synthesizeImu(drive, options, 1);
  ASSERT_FALSE(samples.empty());
  EXPECT_EQ(samples.front().acc_bias, bias.acc_mps2);
  EXPECT_EQ(samples.front().gyr_bias, bias.gyr_radps);
  Eigen::Vector3d acc = Eigen::Vector3d::Zero(), gyr = Eigen::Vector3d::Zero();
  for (const ImuSimSample& s : samples) {
    acc += s.measured.acc_b_mps2 - s.truth.acc_b_mps2;
    gyr += s.measured.gyr_b_radps - s.truth.gyr_b_radps;
  }
  const auto n = static_cast<double>(samples.size());
  EXPECT_LT((acc / n - bias.acc_mps2).norm(), 0.01);
  EXPECT_LT((gyr / n - bias.gyr_radps).norm(), 1e-3);
}

}  // namespace
}  // namespace gvio::sim
