#include "sim/sim_config.hpp"

#include <fmt/format.h>

#include <cmath>

#include "odometry/error.hpp"
#include "sim/world.hpp"

namespace gvio::sim {
namespace {

void require(bool ok, const char* key, const char* what, double value) {
  if (!ok) throw InvalidInput(fmt::format("config: sim.{} must be {} (got {})", key, what, value));
}

}  // namespace

void SimConfig::validate() const {
  require(std::abs(origin_lat_deg) <= 90.0, "origin_lat_deg", "within [-90, 90]", origin_lat_deg);
  require(std::abs(origin_lon_deg) <= 180.0, "origin_lon_deg", "within [-180, 180]",
          origin_lon_deg);
  require(std::isfinite(origin_h_m), "origin_h_m", "finite", origin_h_m);
  require(std::isfinite(heading_deg), "heading_deg", "finite", heading_deg);
  require(camera_rate_hz > 0.0 && camera_rate_hz <= 100.0, "camera_rate_hz", "in (0, 100]",
          camera_rate_hz);
  require(imu_rate_hz >= camera_rate_hz && imu_rate_hz <= 2000.0, "imu_rate_hz",
          "in [camera rate, 2000]", imu_rate_hz);
  require(gnss_rate_hz == 1.0 || gnss_rate_hz == 5.0 || gnss_rate_hz == 10.0, "gnss_rate_hz",
          "1, 5 or 10", gnss_rate_hz);
  require(gnss_lever_arm_m.allFinite(), "gnss_lever_arm_m", "finite", gnss_lever_arm_m.norm());
  require(image_noise_dn >= 0.0 && image_noise_dn <= 50.0, "image_noise_dn", "in [0, 50]",
          image_noise_dn);
  require(exposure_amplitude >= 0.0 && exposure_amplitude < 1.0, "exposure_amplitude", "in [0, 1)",
          exposure_amplitude);
  require(exposure_period_s > 0.0, "exposure_period_s", "positive", exposure_period_s);
  require(right_camera_gain >= 0.25 && right_camera_gain <= 4.0, "right_camera_gain",
          "in [0.25, 4]", right_camera_gain);
  require(exposure_time_s > 0.0 && exposure_time_s < 1.0 / camera_rate_hz, "exposure_time_s",
          "positive and shorter than a frame", exposure_time_s);
  require(blur_samples >= 2 && blur_samples <= 32, "blur_samples", "in [2, 32]", blur_samples);
  require(std::isfinite(camera_time_offset_s) && std::abs(camera_time_offset_s) < 1.0,
          "camera_time_offset_s", "within (-1, 1) s", camera_time_offset_s);
  require(knot_spacing_s >= 0.05 && knot_spacing_s <= 5.0, "knot_spacing_s", "in [0.05, 5]",
          knot_spacing_s);
  require(smoothing >= 0.0 && std::isfinite(smoothing), "smoothing", "finite and >= 0", smoothing);
  require(texture_size_px >= 64 && texture_size_px <= 4096 &&
              (texture_size_px & (texture_size_px - 1)) == 0,
          "texture_size_px", "a power of two in [64, 4096]", texture_size_px);
  if (ros2bag_storage != "mcap" && ros2bag_storage != "sqlite3") {
    throw InvalidInput("config: sim.ros2bag_storage must be mcap or sqlite3 (got '" +
                       ros2bag_storage + "')");
  }
  if (ros2bag_compression != "none" && ros2bag_compression != "lz4" &&
      ros2bag_compression != "zstd") {
    throw InvalidInput("config: sim.ros2bag_compression must be none, lz4 or zstd (got '" +
                       ros2bag_compression + "')");
  }
  if (!parseWorldStyle(world_style)) {
    throw InvalidInput(fmt::format("config: sim.world_style must be one of {} (got '{}')",
                                   kWorldStyleNames, world_style));
  }
  require(imu_noise_scale_min >= 0.01 && imu_noise_scale_min <= 100.0, "imu_noise_scale_min",
          "in [0.01, 100]", imu_noise_scale_min);
  require(imu_noise_scale_max >= imu_noise_scale_min && imu_noise_scale_max <= 100.0,
          "imu_noise_scale_max", "in [sim.imu_noise_scale_min, 100]", imu_noise_scale_max);
  require(imu_turn_on_acc_bias_mps2 >= 0.0 && imu_turn_on_acc_bias_mps2 <= 5.0,
          "imu_turn_on_acc_bias_mps2", "in [0, 5]", imu_turn_on_acc_bias_mps2);
  require(imu_turn_on_gyr_bias_radps >= 0.0 && imu_turn_on_gyr_bias_radps <= 0.5,
          "imu_turn_on_gyr_bias_radps", "in [0, 0.5]", imu_turn_on_gyr_bias_radps);
}

}  // namespace gvio::sim
