#include "odometry/measurements.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"

namespace gvio {

void ImuNoise::validate() const {
  const std::pair<const char*, double> values[] = {{"acc_noise_density", acc_noise_density},
                                                   {"gyr_noise_density", gyr_noise_density},
                                                   {"acc_random_walk", acc_random_walk},
                                                   {"gyr_random_walk", gyr_random_walk}};
  for (const auto& [key, value] : values) {
    if (!std::isfinite(value) || value <= 0.0) {
      throw InvalidInput(std::string("config: imu.") + key + " must be a positive number (got " +
                         std::to_string(value) + ")");
    }
  }
}

}  // namespace gvio
