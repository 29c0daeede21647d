#include "odometry/vio_config.hpp"

#include <cmath>
#include <string>

#include "odometry/error.hpp"

namespace gvio::odometry {
namespace {

void require(bool ok, const std::string& field, const std::string& what) {
  if (!ok) throw InvalidInput("config: vio." + field + " must be " + what);
}

bool positive(double v) {
  return std::isfinite(v) && v > 0.0;
}

bool nonNegative(double v) {
  return std::isfinite(v) && v >= 0.0;
}

}  // namespace

std::string toString(VioMode mode) {
  switch (mode) {
    case VioMode::kStereoImu:
      return "stereo-imu";
    case VioMode::kMonoImu:
      return "mono-imu";
    case VioMode::kStereo:
      return "stereo";
  }
  return "?";
}

VioMode parseVioMode(const std::string& name) {
  if (name == "stereo-imu") return VioMode::kStereoImu;
  if (name == "mono-imu") return VioMode::kMonoImu;
  if (name == "stereo") return VioMode::kStereo;
  throw InvalidInput("config: vio.mode must be one of stereo-imu, mono-imu, stereo (got '" + name +
                     "')");
}

std::string toString(FoldedLandmarks policy) {
  switch (policy) {
    case FoldedLandmarks::kAuto:
      return "auto";
    case FoldedLandmarks::kDrop:
      return "drop";
    case FoldedLandmarks::kReanchor:
      return "reanchor";
  }
  return "?";
}

FoldedLandmarks parseFoldedLandmarks(const std::string& name) {
  if (name == "auto") return FoldedLandmarks::kAuto;
  if (name == "drop") return FoldedLandmarks::kDrop;
  if (name == "reanchor") return FoldedLandmarks::kReanchor;
  throw InvalidInput("config: vio.folded_landmarks must be one of auto, drop, reanchor (got '" +
                     name + "')");
}

bool EstimatorConfig::foldedLandmarksDropped() const {
  if (folded_landmarks == FoldedLandmarks::kAuto) return usesImu(mode);
  return folded_landmarks == FoldedLandmarks::kDrop;
}

int EstimatorConfig::solverIterations() const {
  if (max_iterations > 0) return max_iterations;
  return mode == VioMode::kStereoImu ? 2 : 4;
}

void EstimatorConfig::validate() const {
  tracker.validate();
  if (usesImu(mode)) imu_noise.validate();
  require(window_size >= 3 && window_size <= 50, "window_size", "in [3, 50]");
  require(positive(keyframe_parallax_deg) && keyframe_parallax_deg < 45.0, "keyframe_parallax_deg",
          "in (0, 45)");
  require(keyframe_min_tracked >= 1, "keyframe_min_tracked", ">= 1");
  require(positive(pixel_sigma_px), "pixel_sigma_px", "> 0");
  require(positive(huber_sigmas), "huber_sigmas", "> 0");
  require(max_iterations >= 0 && max_iterations <= 100, "max_iterations",
          "auto (0) or in [1, 100]");
  require(positive(min_depth_m), "min_depth_m", "> 0");
  require(positive(max_depth_m) && max_depth_m > min_depth_m, "max_depth_m", "> min_depth_m");
  require(positive(max_reprojection_px), "max_reprojection_px", "> 0");
  require(positive(static_gyr_radps), "static_gyr_radps", "> 0");
  require(positive(static_acc_mps2), "static_acc_mps2", "> 0");
  require(positive(static_pixel_motion_px), "static_pixel_motion_px", "> 0");
  require(positive(init_window_s), "init_window_s", "> 0");
  require(positive(init_max_tilt_sigma_deg), "init_max_tilt_sigma_deg", "> 0");
  require(nonNegative(init_max_wait_s), "init_max_wait_s", ">= 0");
  require(nonNegative(init_alignment_span_s), "init_alignment_span_s", ">= 0");
  require(positive(max_imu_gap_s), "max_imu_gap_s", "> 0");
  require(positive(init_tilt_sigma_deg), "init_tilt_sigma_deg", "> 0");
  require(positive(init_velocity_sigma_mps), "init_velocity_sigma_mps", "> 0");
  require(positive(acc_bias_prior_mps2), "acc_bias_prior_mps2", "> 0");
  require(positive(time_offset_sigma_s), "time_offset_sigma_s", "> 0");
  require(nonNegative(time_offset_random_walk_s), "time_offset_random_walk_s", ">= 0");
  require(nonNegative(time_offset_min_rate_change_radps), "time_offset_min_rate_change_radps",
          ">= 0");
  require(nonNegative(time_offset_min_force_change_mps2), "time_offset_min_force_change_mps2",
          ">= 0");
  require(time_offset_hold_median_solves >= 1, "time_offset_hold_median_solves", ">= 1");
  require(positive(gyr_bias_prior_radps), "gyr_bias_prior_radps", "> 0");
  require(min_features_tracking >= 5, "min_features_tracking", ">= 5");
}

}  // namespace gvio::odometry
