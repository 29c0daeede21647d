#include "sim/camera_sim.hpp"

#include <cmath>
#include <opencv2/core.hpp>

namespace gvio::sim {

CameraSimulator::CameraSimulator(const render::EglContext& context, const render::Scene& world,
                                 const render::PinholeIntrinsics& K,
                                 std::vector<Eigen::Isometry3d> T_b_c, const SimConfig& config,
                                 std::uint64_t seed)
    : renderer_(context),
      scene_(world),
      target_(K.width, K.height),
      K_(K),
      T_b_c_(std::move(T_b_c)),
      config_(config),
      seed_(seed) {}

cv::Mat CameraSimulator::renderAt(const ContinuousTrajectory& trajectory, std::int64_t t_ns,
                                  std::size_t camera, float gain) {
  const Eigen::Isometry3d T_w_c = trajectory.at(t_ns).pose() * T_b_c_[camera];
  render::DrawOptions options;
  options.exposure_gain = gain;
  const render::ImageRgba rgba =
      renderer_.renderColor(scene_, render::pinholeCamera(K_, T_w_c), target_, options);
  cv::Mat grey(rgba.height, rgba.width, CV_8UC1);
  for (int y = 0; y < rgba.height; ++y) {
    auto* row = grey.ptr<std::uint8_t>(y);
    for (int x = 0; x < rgba.width; ++x) row[x] = rgba.pixel(x, y)[0];  // grey textures: R = G = B
  }
  return grey;
}

cv::Mat CameraSimulator::render(const ContinuousTrajectory& trajectory, std::int64_t t_ns,
                                std::size_t camera, std::uint64_t frame_index) {
  float gain = 1.0F;
  if (config_.exposure_change) {
    const double t_s = 1e-9 * static_cast<double>(t_ns - trajectory.t0_ns());
    gain = static_cast<float>(1.0 + config_.exposure_amplitude *
                                        std::sin(2.0 * M_PI * t_s / config_.exposure_period_s));
  }
  if (camera == 1) gain *= static_cast<float>(config_.right_camera_gain);
  cv::Mat image;
  if (config_.motion_blur) {
    // Average renders spread over the exposure: the stereo pair is triggered together, so both
    // cameras blur over the same interval.
    cv::Mat sum = cv::Mat::zeros(K_.height, K_.width, CV_32F);
    for (int k = 0; k < config_.blur_samples; ++k) {
      const auto dt = static_cast<std::int64_t>(
          std::llround(1e9 * config_.exposure_time_s * k / (config_.blur_samples - 1)));
      cv::Mat f;
      renderAt(trajectory, t_ns + dt, camera, gain).convertTo(f, CV_32F);
      sum += f;
    }
    image = sum / config_.blur_samples;
  } else {
    renderAt(trajectory, t_ns, camera, gain).convertTo(image, CV_32F);
  }
  if (config_.image_noise_dn > 0.0) {
    Rng rng(mixSeed(seed_, frame_index, camera + 1));
    for (int y = 0; y < image.rows; ++y) {
      auto* row = image.ptr<float>(y);
      for (int x = 0; x < image.cols; ++x)
        row[x] += static_cast<float>(config_.image_noise_dn * rng.normal());
    }
  }
  cv::Mat out;
  image.convertTo(out, CV_8U);  // rounds and saturates to [0, 255]
  return out;
}

}  // namespace gvio::sim
