#include "sim/dataset_writers.hpp"

#include <fmt/format.h>

#include <sstream>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::sim {
namespace fs = std::filesystem;
namespace {

// KITTI's roll (left side up), pitch (front down), yaw (0 = east, counter-clockwise) are the ZYX
// Euler angles of the body (x forward, y left, z up) in ENU.
Eigen::Vector3d kittiRollPitchYaw(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
}

std::string vec(const Eigen::Vector3d& v) {
  return fmt::format("{:.9f} {:.9f} {:.9f}", v.x(), v.y(), v.z());
}

void writeLines(const fs::path& file, const std::string& text) {
  io::writeTextAtomic(file, text);
}

}  // namespace

void writeKittiOxts(const fs::path& drive, const std::vector<ImuSimSample>& imu,
                    const ContinuousTrajectory& trajectory, const fusion::EnuFrame& enu) {
  fs::create_directories(drive / "oxts" / "data");
  std::string stamps;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    const std::int64_t t = imu[i].measured.t_ns;
    const BodyState s = trajectory.at(t);
    const fusion::Lla lla = enu.toLla(s.p_w);
    const Eigen::Vector3d rpy = kittiRollPitchYaw(s.R_w_b);
    const Eigen::Vector3d v_b = s.R_w_b.transpose() * s.v_w;
    const Eigen::Vector3d& f = imu[i].measured.acc_b_mps2;
    const Eigen::Vector3d& w = imu[i].measured.gyr_b_radps;
    // lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz wf wl wu
    // pos_accuracy vel_accuracy navstat numsats posmode velmode orimode (devkit dataformat.txt)
    const std::string record =
        fmt::format("{:.12f} {:.12f} {:.6f} {} {:.9f} {:.9f} {} {} {} {} {} 0.01 0.01 4 12 4 4 6\n",
                    lla.lat_deg, lla.lon_deg, lla.h_ellipsoid_m, vec(rpy), s.v_w.y(), s.v_w.x(),
                    vec(v_b), vec(f), vec(f), vec(w), vec(w));
    writeLines(drive / "oxts" / "data" / fmt::format("{:010d}.txt", i), record);
    stamps += io::formatKittiTimestamp(t) + "\n";
  }
  writeLines(drive / "oxts" / "timestamps.txt", stamps);
}

void writeImuTruth(const fs::path& file, const std::vector<ImuSimSample>& imu) {
  std::string csv =
      "#timestamp [ns],f_x [m s^-2],f_y [m s^-2],f_z [m s^-2],w_x [rad s^-1],w_y [rad s^-1],w_z "
      "[rad s^-1],"
      "b_a_x [m s^-2],b_a_y [m s^-2],b_a_z [m s^-2],b_w_x [rad s^-1],b_w_y [rad s^-1],b_w_z [rad "
      "s^-1]\n";
  for (const auto& s : imu) {
    const auto& t = s.truth;
    csv += fmt::format(
        "{},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:."
        "9e}\n",
        t.t_ns, t.acc_b_mps2.x(), t.acc_b_mps2.y(), t.acc_b_mps2.z(), t.gyr_b_radps.x(),
        t.gyr_b_radps.y(), t.gyr_b_radps.z(), s.acc_bias.x(), s.acc_bias.y(), s.acc_bias.z(),
        s.gyr_bias.x(), s.gyr_bias.y(), s.gyr_bias.z());
  }
  writeLines(file, csv);
}

fs::path kittiImagePath(const fs::path& drive, int camera, std::size_t index) {
  return drive / fmt::format("image_{:02d}", camera) / "data" / fmt::format("{:010d}.png", index);
}

void writeKittiImageStamps(const fs::path& drive, int camera,
                           const std::vector<std::int64_t>& t_ns) {
  std::string stamps;
  for (const auto t : t_ns) stamps += io::formatKittiTimestamp(t) + "\n";
  writeLines(drive / fmt::format("image_{:02d}", camera) / "timestamps.txt", stamps);
}

fs::path eurocImagePath(const fs::path& root, int camera, std::int64_t t_ns) {
  return root / "mav0" / fmt::format("cam{}", camera) / "data" / fmt::format("{}.png", t_ns);
}

void writeEurocCamera(const fs::path& root, int camera, const std::vector<std::int64_t>& t_ns,
                      const render::PinholeIntrinsics& K, const Eigen::Isometry3d& T_b_c,
                      double rate_hz) {
  const fs::path dir = root / "mav0" / fmt::format("cam{}", camera);
  std::string csv = "#timestamp [ns],filename\n";
  for (const auto t : t_ns) csv += fmt::format("{},{}.png\n", t, t);
  writeLines(dir / "data.csv", csv);
  const Eigen::Matrix4d T = T_b_c.matrix();
  std::string yaml =
      "%YAML:1.0\nsensor_type: camera\ncomment: gvio simulated camera\nT_BS:\n  cols: 4\n  rows: "
      "4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) yaml += fmt::format("{}{:.12f}", r + c ? ", " : "", T(r, c));
  }
  yaml += fmt::format("]\nrate_hz: {}\nresolution: [{}, {}]\ncamera_model: pinhole\n", rate_hz,
                      K.width, K.height);
  yaml += fmt::format("intrinsics: [{}, {}, {}, {}]\ndistortion_model: radial-tangential\n", K.fx,
                      K.fy, K.cx, K.cy);
  yaml += "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n";
  writeLines(dir / "sensor.yaml", yaml);
}

void writeEurocImu(const fs::path& root, const std::vector<ImuSimSample>& imu,
                   const ImuNoise& noise, double rate_hz) {
  const fs::path dir = root / "mav0" / "imu0";
  fs::create_directories(dir);
  std::string csv =
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m "
      "s^-2],"
      "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (const auto& s : imu) {
    const auto& m = s.measured;
    csv += fmt::format("{},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f}\n", m.t_ns,
                       m.gyr_b_radps.x(), m.gyr_b_radps.y(), m.gyr_b_radps.z(), m.acc_b_mps2.x(),
                       m.acc_b_mps2.y(), m.acc_b_mps2.z());
  }
  writeLines(dir / "data.csv", csv);
  writeLines(
      dir / "sensor.yaml",
      fmt::format(
          "%YAML:1.0\nsensor_type: imu\ncomment: gvio simulated IMU\nT_BS:\n  cols: 4\n  rows: 4\n"
          "  data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, "
          "1.0]\n"
          "rate_hz: {}\ngyroscope_noise_density: {}\ngyroscope_random_walk: {}\n"
          "accelerometer_noise_density: {}\naccelerometer_random_walk: {}\n",
          rate_hz, noise.gyr_noise_density, noise.gyr_random_walk, noise.acc_noise_density,
          noise.acc_random_walk));
}

void writeEurocGnss(const fs::path& root, const std::vector<GnssFix>& fixes) {
  fs::create_directories(root / "mav0" / "gnss0");
  writeLines(root / "mav0" / "gnss0" / "data.csv", toGnssCsv(fixes));
}

void writeEurocTruth(const fs::path& root, const std::vector<ImuSimSample>& imu,
                     const ContinuousTrajectory& trajectory) {
  const fs::path dir = root / "mav0" / "state_groundtruth_estimate0";
  fs::create_directories(dir);
  std::string csv =
      "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z "
      "[],v_RS_R_x [m s^-1],"
      "v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],b_w_RS_S_x [rad s^-1],b_w_RS_S_y [rad s^-1],b_w_RS_S_z "
      "[rad s^-1],"
      "b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],b_a_RS_S_z [m s^-2]\n";
  for (const auto& s : imu) {
    const BodyState b = trajectory.at(s.measured.t_ns);
    const Eigen::Quaterniond q(b.R_w_b);
    csv += fmt::format(
        "{},{:.9f},{:.9f},{:.9f},{:.12f},{:.12f},{:.12f},{:.12f},{:.9f},{:.9f},{:.9f},{:.9e},{:.9e}"
        ","
        "{:.9e},{:.9e},{:.9e},{:.9e}\n",
        s.measured.t_ns, b.p_w.x(), b.p_w.y(), b.p_w.z(), q.w(), q.x(), q.y(), q.z(), b.v_w.x(),
        b.v_w.y(), b.v_w.z(), s.gyr_bias.x(), s.gyr_bias.y(), s.gyr_bias.z(), s.acc_bias.x(),
        s.acc_bias.y(), s.acc_bias.z());
  }
  writeLines(dir / "data.csv", csv);
}

}  // namespace gvio::sim
