#include "io/kalibr_writer.hpp"

#include <fmt/format.h>

#include "odometry/error.hpp"

namespace gvio::io {
namespace {

// Shortest round-trip form of every number: a reader gets back the very doubles written.
std::string matrixYaml(const Eigen::Matrix4d& m, const char* indent) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{}- [{}, {}, {}, {}]\n", indent, m(r, 0), m(r, 1), m(r, 2), m(r, 3));
  }
  return out;
}

}  // namespace

std::string kalibrCamchainYaml(const std::vector<CameraModel>& cameras,
                               const std::vector<std::string>& topics, double timeshift_cam_imu_s) {
  if (topics.size() != cameras.size()) {
    throw InvalidInput("kalibrCamchainYaml: one topic per camera");
  }
  std::string out;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const CameraModel& cam = cameras[i];
    // Kalibr's radtan has no k3: OpenCV's 5-coefficient form is written only when k3 is 0.
    const bool plain_k3 = cam.distortion_model == Distortion::kRadtan &&
                          cam.distortion.size() == 5 && cam.distortion[4] == 0.0;
    if (!cam.distortion.empty() && cam.distortion.size() != 4 && !plain_k3) {
      throw InvalidInput(
          "kalibrCamchainYaml: radtan and equidistant take 4 coefficients (radtan 5 with k3 0)");
    }
    const Eigen::Isometry3d T_cam_imu = cam.T_b_c.inverse();
    out += fmt::format("cam{}:\n  T_cam_imu:\n{}", i, matrixYaml(T_cam_imu.matrix(), "  "));
    if (i > 0) {
      const Eigen::Isometry3d T_cn_cnm1 = T_cam_imu * cameras[i - 1].T_b_c;
      out += "  T_cn_cnm1:\n" + matrixYaml(T_cn_cnm1.matrix(), "  ");
    }
    const std::vector<double> d =
        cam.distortion.empty() ? std::vector<double>(4, 0.0) : cam.distortion;
    out += fmt::format(
        "  camera_model: pinhole\n  distortion_coeffs: [{}, {}, {}, {}]\n  distortion_model: "
        "{}\n  intrinsics: [{}, {}, {}, {}]\n  resolution: [{}, {}]\n  rostopic: {}\n  "
        "timeshift_cam_imu: {}\n",
        d[0], d[1], d[2], d[3],
        cam.distortion_model == Distortion::kEquidistant ? "equidistant" : "radtan", cam.fx, cam.fy,
        cam.cx, cam.cy, cam.width_px, cam.height_px, topics[i], timeshift_cam_imu_s);
  }
  return out;
}

std::string kalibrImuYaml(const ImuNoise& noise, double rate_hz, const std::string& topic) {
  return fmt::format(
      "imu0:\n  T_i_b:\n{}  accelerometer_noise_density: {}\n  accelerometer_random_walk: {}\n  "
      "gyroscope_noise_density: {}\n  gyroscope_random_walk: {}\n  model: calibrated\n  rostopic: "
      "{}\n  time_offset: 0.0\n  update_rate: {}\n",
      matrixYaml(Eigen::Matrix4d::Identity(), "  "), noise.acc_noise_density, noise.acc_random_walk,
      noise.gyr_noise_density, noise.gyr_random_walk, topic, rate_hz);
}

}  // namespace gvio::io
