#include "run/run_config.hpp"

#include <cstdio>

#include "odometry/error.hpp"

namespace gvio::run {

std::optional<fusion::Lla> FusionAppConfig::originLla() const {
  if (origin == "first-fix") return std::nullopt;
  fusion::Lla lla;
  char tail = 0;
  if (std::sscanf(origin.c_str(), "%lf,%lf,%lf%c", &lla.lat_deg, &lla.lon_deg, &lla.h_ellipsoid_m,
                  &tail) != 3 ||
      !fusion::isValidLla(lla)) {
    throw InvalidInput("config: fusion.origin must be first-fix or lat,lon,h (got '" + origin +
                       "')");
  }
  return lla;
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
  imu.noise.validate();
  vio.validate();
  fusion.validate();
  map.map.validate();
  loops.validate();
}

}  // namespace gvio::run
