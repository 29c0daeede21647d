#pragma once
// IMU measurements from a continuous trajectory: specific force f_b = R_w_b^T (a_w - g_w) and body
// rate, plus white noise and bias random walk (continuous-time densities, discretised at the rate).
#include <array>
#include <cstdint>
#include <vector>

#include "odometry/measurements.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {

struct ImuSimSample {
  ImuSample measured;  // what the sensor outputs (noise and bias included)
  ImuSample truth;     // noise-free specific force and rate
  Eigen::Vector3d acc_bias = Eigen::Vector3d::Zero(), gyr_bias = Eigen::Vector3d::Zero();
};

struct ImuSimOptions {
  double rate_hz = 100.0;
  ImuNoise noise;         // densities; all zero = noise-free
  bool add_noise = true;  // false: measured == truth, biases zero
  Eigen::Vector3d initial_acc_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_gyr_bias = Eigen::Vector3d::Zero();
};

// One drive's IMU noise: the nominal densities (imu.*), each times a multiplier drawn
// log-uniformly in [scale_min, scale_max] (independently, in the order acc noise, gyr noise, acc
// random walk, gyr random walk), so drives differ from what an estimator is tuned for.
// scale_min == scale_max: no draw, the multiplier is that value exactly.
struct ImuNoiseDraw {
  ImuNoise noise;
  std::array<double, 4> scale{1.0, 1.0, 1.0, 1.0};
};
ImuNoiseDraw drawImuNoise(const ImuNoise& nominal, double scale_min, double scale_max,
                          std::uint64_t seed);

// One drive's turn-on biases: each axis N(0, sigma^2) by seed (a MEMS IMU starts every drive with
// another bias, which a filter must estimate; 0 sigma: none).
struct TurnOnBias {
  Eigen::Vector3d acc_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyr_radps = Eigen::Vector3d::Zero();
};
TurnOnBias drawTurnOnBias(double acc_sigma_mps2, double gyr_sigma_radps, std::uint64_t seed);

// Samples [t0, t1] of `trajectory` at the rate; deterministic for a seed.
std::vector<ImuSimSample> synthesizeImu(const ContinuousTrajectory& trajectory,
                                        const ImuSimOptions& options, std::uint64_t seed);

}  // namespace gvio::sim
