#include "sim/imu_synth.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"
#include "sim/rng.hpp"

namespace gvio::sim {
namespace {

constexpr double kNsPerS = 1e9;

void validateOptions(const ImuSimOptions& options) {
  if (!std::isfinite(options.rate_hz) || options.rate_hz <= 0.0) {
    throw InvalidInput("imu synthesis: rate_hz must be a positive number (got " +
                       std::to_string(options.rate_hz) + ")");
  }
  if (!options.add_noise) return;
  const ImuNoise& n = options.noise;
  for (const double density :
       {n.acc_noise_density, n.gyr_noise_density, n.acc_random_walk, n.gyr_random_walk}) {
    if (!std::isfinite(density) || density < 0.0) {
      throw InvalidInput("imu synthesis: noise densities must be finite and >= 0");
    }
  }
  if (!options.initial_acc_bias.allFinite() || !options.initial_gyr_bias.allFinite()) {
    throw InvalidInput("imu synthesis: initial biases must be finite");
  }
}

// Sample k lies at t0 + round(k * 1e9 / rate) ns: rounding each stamp from t0 (not accumulating
// a rounded period) keeps the stamps from drifting at rates whose period is not whole ns.
std::vector<std::int64_t> sampleTimes(std::int64_t t0_ns, std::int64_t t1_ns, double rate_hz) {
  std::vector<std::int64_t> stamps;
  for (std::int64_t k = 0;; ++k) {
    const std::int64_t t_ns = t0_ns + std::llround(static_cast<double>(k) * kNsPerS / rate_hz);
    if (t_ns > t1_ns) break;
    stamps.push_back(t_ns);
  }
  return stamps;
}

// Noise-free IMU output: specific force f_b = R_w_b^T (a_w - g_w), g_w = (0, 0, -g) in ENU, and
// the body angular rate.
ImuSample truthAt(const ContinuousTrajectory& trajectory, std::int64_t t_ns) {
  const BodyState state = trajectory.at(t_ns);
  const Eigen::Vector3d g_w(0.0, 0.0, -kGravity_mps2);
  ImuSample sample;
  sample.t_ns = t_ns;
  sample.acc_b_mps2 = state.R_w_b.transpose() * (state.a_w - g_w);
  sample.gyr_b_radps = state.omega_b;
  return sample;
}

}  // namespace

ImuNoiseDraw drawImuNoise(const ImuNoise& nominal, double scale_min, double scale_max,
                          std::uint64_t seed) {
  if (!(scale_min > 0.0) || !(scale_max >= scale_min) || !std::isfinite(scale_max)) {
    throw InvalidInput("imu noise draw: needs 0 < scale_min <= scale_max");
  }
  ImuNoiseDraw draw;
  Rng rng(seed);
  for (double& scale : draw.scale) {
    scale = scale_min == scale_max
                ? scale_min
                : std::exp(rng.uniform(std::log(scale_min), std::log(scale_max)));
  }
  draw.noise = nominal;
  draw.noise.acc_noise_density *= draw.scale[0];
  draw.noise.gyr_noise_density *= draw.scale[1];
  draw.noise.acc_random_walk *= draw.scale[2];
  draw.noise.gyr_random_walk *= draw.scale[3];
  return draw;
}

TurnOnBias drawTurnOnBias(double acc_sigma_mps2, double gyr_sigma_radps, std::uint64_t seed) {
  if (!(acc_sigma_mps2 >= 0.0) || !(gyr_sigma_radps >= 0.0) || !std::isfinite(acc_sigma_mps2) ||
      !std::isfinite(gyr_sigma_radps)) {
    throw InvalidInput("imu turn-on bias: sigmas must be finite and >= 0");
  }
  Rng rng(seed);
  TurnOnBias bias;
  // Always draw both, so that one sigma does not change the other's values.
  bias.acc_mps2 = acc_sigma_mps2 * rng.normal3();
  bias.gyr_radps = gyr_sigma_radps * rng.normal3();
  return bias;
}

// Discrete-time IMU noise model (Kalibr IMU noise model wiki; Nikolic et al. 2016): white noise
// sigma_d = sigma_c * sqrt(rate) and bias random walk b_{k+1} = b_k + sigma_bc * sqrt(dt) * n_k,
// n_k ~ N(0, I); measured = truth + b_k + sigma_d * w_k.
std::vector<ImuSimSample> synthesizeImu(const ContinuousTrajectory& trajectory,
                                        const ImuSimOptions& options, std::uint64_t seed) {
  validateOptions(options);
  const std::vector<std::int64_t> stamps =
      sampleTimes(trajectory.t0_ns(), trajectory.t1_ns(), options.rate_hz);

  const ImuNoise& noise = options.noise;
  const double dt_s = 1.0 / options.rate_hz;
  const double sqrt_rate = std::sqrt(options.rate_hz), sqrt_dt = std::sqrt(dt_s);
  Rng gaussian(seed);
  Eigen::Vector3d acc_bias = options.initial_acc_bias, gyr_bias = options.initial_gyr_bias;

  std::vector<ImuSimSample> samples;
  samples.reserve(stamps.size());
  for (const std::int64_t t_ns : stamps) {
    ImuSimSample sample;
    sample.truth = truthAt(trajectory, t_ns);
    sample.measured = sample.truth;
    if (options.add_noise) {
      sample.acc_bias = acc_bias;
      sample.gyr_bias = gyr_bias;
      sample.measured.acc_b_mps2 +=
          acc_bias + noise.acc_noise_density * sqrt_rate * gaussian.normal3();
      sample.measured.gyr_b_radps +=
          gyr_bias + noise.gyr_noise_density * sqrt_rate * gaussian.normal3();
      acc_bias += noise.acc_random_walk * sqrt_dt * gaussian.normal3();
      gyr_bias += noise.gyr_random_walk * sqrt_dt * gaussian.normal3();
    }
    samples.push_back(sample);
  }
  return samples;
}

}  // namespace gvio::sim
