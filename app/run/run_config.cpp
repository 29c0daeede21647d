#include "run/run_config.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"

namespace gvio::run {

ImuConfig::Choice ImuConfig::choose(const std::optional<ImuNoise>& dataset_noise) const {
  if (!dataset_noise || !prefer_dataset_noise) return {noise, "config"};
  ImuNoise scaled = *dataset_noise;
  scaled.acc_noise_density *= dataset_noise_scale;
  scaled.gyr_noise_density *= dataset_noise_scale;
  scaled.acc_random_walk *= dataset_noise_scale;
  scaled.gyr_random_walk *= dataset_noise_scale;
  return {scaled, "dataset"};
}

void ImuConfig::validate() const {
  if (!std::isfinite(dataset_noise_scale) || dataset_noise_scale <= 0.0) {
    throw InvalidInput("config: imu.dataset_noise_scale must be a positive number (got " +
                       std::to_string(dataset_noise_scale) + ")");
  }
  noise.validate();
}

std::optional<fusion::Lla> FusionAppConfig::originLla() const {
  if (origin == "first-fix") return std::nullopt;
  const auto lla = fusion::parseLla(origin);
  if (!lla) {
    throw InvalidInput("config: fusion.origin must be first-fix or lat,lon,h (got '" + origin +
                       "')");
  }
  return lla;
}

// The VIO's relative-motion noise in the fusion's graphs by VIO mode. Stereo+IMU: the medians
// of its relative error (SE(3), 3-D) at 10 m and 100 m over the 15 drives of the style matrix,
// read as a random walk over keyframe steps of about 0.8 m: 0.2 % + 1 cm and 2e-4 rad per step
// (KITTI-00 SPP graph 0.913 -> 0.843 m; docs/how-it-works/loops.md). Mono+IMU (scale drift) and
// stereo alone (rotation drift, no tilt from gravity) measured worse with it and keep the
// library's 0.4 % + 2 cm and 5e-4 rad.
fusion::FusionConfig FusionAppConfig::fusionFor(std::optional<odometry::VioMode> mode) const {
  fusion::FusionConfig c = fusion;
  if (mode == odometry::VioMode::kStereoImu) {
    c.vio_drift_fraction = 0.002;
    c.vio_sigma_floor_m = 0.01;
    c.vio_rot_floor_rad = 2e-4;
  }
  // Anything but 0 (auto) is the user's, checked by FusionConfig::validate (validate() below).
  if (vio_drift_fraction != 0.0) c.vio_drift_fraction = vio_drift_fraction;
  if (vio_sigma_floor_m != 0.0) c.vio_sigma_floor_m = vio_sigma_floor_m;
  if (vio_rot_floor_rad != 0.0) c.vio_rot_floor_rad = vio_rot_floor_rad;
  return c;
}

fusion::InsConfig FusionAppConfig::insConfig(const ImuNoise& imu_noise) const {
  fusion::InsConfig c = ins;
  c.lever_arm_b = fusion.lever_arm_b;
  c.receiver_time_offset_s = fusion.receiver_time_offset_s;
  c.gate_chi2 = fusion.gate_chi2;
  c.max_consecutive_rejections = fusion.max_consecutive_rejections;
  c.outage_s = fusion.outage_s;
  c.imu = imu_noise;
  return c;
}

void FusionAppConfig::validate() const {
  (void)originLla();
  fusion.validate();
  fusionFor(std::nullopt).validate();  // the VIO noise values set (the auto ones are fusion's)
  insConfig(ImuNoise{}).validate();
}

void VioConfig::validate() const {
  if (mode != "auto" && mode != "stereo-imu" && mode != "mono-imu" && mode != "stereo") {
    throw InvalidInput("config: vio.mode must be one of auto, stereo-imu, mono-imu, stereo (got '" +
                       mode + "')");
  }
  try {
    estimator.validate();
  } catch (const InvalidInput& e) {
    // The tracker names its keys from its own section; here they live under vio.tracker.
    const std::string what = e.what();
    const std::string prefix = "config: tracker.";
    if (what.rfind(prefix, 0) == 0) {
      throw InvalidInput("config: vio.tracker." + what.substr(prefix.size()));
    }
    throw;
  }
}

void RunConfig::validate() const {
  dataset.validate();
  imu.validate();
  vio.validate();
  fusion.validate();
  map.map.validate();
  loops.validate();
}

}  // namespace gvio::run
