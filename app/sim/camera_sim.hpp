#pragma once
// Synthetic grey camera images: the world rendered through the exact pinhole camera at the
// camera's true pose, then the sensor effects: optional motion blur (renders averaged over the
// exposure), optional slow exposure change, Gaussian pixel noise. Deterministic per (seed, frame,
// camera), so frames can be produced in any order.
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <vector>

#include "render/renderer.hpp"
#include "sim/rng.hpp"
#include "sim/sim_config.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {

class CameraSimulator {
 public:
  // `T_b_c` per camera (body = IMU frame). Needs the context current; uploads the world once.
  CameraSimulator(const render::EglContext& context, const render::Scene& world,
                  const render::PinholeIntrinsics& K, std::vector<Eigen::Isometry3d> T_b_c,
                  const SimConfig& config, std::uint64_t seed);

  // 8-bit grey image of camera `camera` for the exposure starting at t_ns.
  [[nodiscard]] cv::Mat render(const ContinuousTrajectory& trajectory, std::int64_t t_ns,
                               std::size_t camera, std::uint64_t frame_index);

 private:
  [[nodiscard]] cv::Mat renderAt(const ContinuousTrajectory& trajectory, std::int64_t t_ns,
                                 std::size_t camera, float gain);

  render::Renderer renderer_;
  render::GpuScene scene_;
  render::Framebuffer target_;
  render::PinholeIntrinsics K_;
  std::vector<Eigen::Isometry3d> T_b_c_;
  SimConfig config_;
  std::uint64_t seed_;
};

}  // namespace gvio::sim
