#include "sim/kitti_convention.hpp"

#include <fmt/format.h>

#include "io/atomic_write.hpp"

namespace gvio::sim {
namespace {

// KITTI raw calibration of 2011_09_26 (calib_imu_to_velo.txt, calib_velo_to_cam.txt).
constexpr double kR_velo_imu[9] = {9.999976e-01,  7.553071e-04, -2.035826e-03,
                                   -7.854027e-04, 9.998898e-01, -1.482298e-02,
                                   2.024406e-03,  1.482454e-02, 9.998881e-01};
constexpr double kT_velo_imu[3] = {-8.086759e-01, 3.195559e-01, -7.997231e-01};
constexpr double kR_cam_velo[9] = {7.533745e-03, -9.999714e-01, -6.166020e-04,
                                   1.480249e-02, 7.280733e-04,  -9.998902e-01,
                                   9.998621e-01, 7.523790e-03,  1.480755e-02};
constexpr double kT_cam_velo[3] = {-4.069766e-03, -7.631618e-02, -2.717806e-01};

Eigen::Isometry3d isometry(const double* R, const double* t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R);
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}

std::string numbers(const double* v, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += fmt::format("{}{:.6e}", i ? " " : "", v[i]);
  return out;
}

}  // namespace

render::PinholeIntrinsics kittiIntrinsics() {
  render::PinholeIntrinsics K;
  K.fx = K.fy = 718.856;
  K.cx = 607.1928;
  K.cy = 185.2157;
  K.width = 1241;
  K.height = 376;
  K.near_m = 0.3;
  K.far_m = 400.0;
  return K;
}

KittiCalibrationText kittiCalibrationText(const render::PinholeIntrinsics& K, bool stereo) {
  KittiCalibrationText text;
  text.imu_to_velo = "calib_time: 25-May-2012 16:47:16\nR: " + numbers(kR_velo_imu, 9) +
                     "\nT: " + numbers(kT_velo_imu, 3) + "\n";
  text.velo_to_cam = "calib_time: 15-Mar-2012 11:37:16\nR: " + numbers(kR_cam_velo, 9) +
                     "\nT: " + numbers(kT_cam_velo, 3) + "\ndelta_f: 0.000000e+00 0.000000e+00\n" +
                     "delta_c: 0.000000e+00 0.000000e+00\n";
  // Raw and rectified calibration coincide: the simulated cameras are ideal pinholes.
  text.cam_to_cam = "calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\n";
  for (int id = 0; id < (stereo ? 2 : 1); ++id) {
    const double tx = id == 0 ? 0.0 : -kKittiBaselineM;  // cam1 sits to the right of cam0
    text.cam_to_cam += fmt::format("S_{0:02d}: {1} {2}\nK_{0:02d}: {3} 0 {4} 0 {5} {6} 0 0 1\n", id,
                                   K.width, K.height, K.fx, K.cx, K.fy, K.cy);
    text.cam_to_cam += fmt::format(
        "D_{0:02d}: 0 0 0 0 0\nR_{0:02d}: 1 0 0 0 1 0 0 0 1\nT_{0:02d}: {1} 0 0\n", id, tx);
    text.cam_to_cam += fmt::format("S_rect_{0:02d}: {1} {2}\nR_rect_{0:02d}: 1 0 0 0 1 0 0 0 1\n",
                                   id, K.width, K.height);
    text.cam_to_cam += fmt::format("P_rect_{0:02d}: {1} 0 {2} {3} 0 {4} {5} 0 0 0 1 0\n", id, K.fx,
                                   K.cx, K.fx * tx, K.fy, K.cy);
  }
  return text;
}

void writeKittiCalibration(const std::filesystem::path& dir, const render::PinholeIntrinsics& K,
                           bool stereo) {
  const KittiCalibrationText text = kittiCalibrationText(K, stereo);
  io::writeTextAtomic(dir / "calib_imu_to_velo.txt", text.imu_to_velo);
  io::writeTextAtomic(dir / "calib_velo_to_cam.txt", text.velo_to_cam);
  io::writeTextAtomic(dir / "calib_cam_to_cam.txt", text.cam_to_cam);
}

Eigen::Isometry3d kittiCamFromImu() {
  return isometry(kR_cam_velo, kT_cam_velo) * isometry(kR_velo_imu, kT_velo_imu);
}

Trajectory kittiCameraToEnuBody(const Trajectory& T_kw_c0, double heading_deg) {
  // KITTI world: x right, y down, z forward of the first camera. Its forward axis points along
  // `heading` in ENU, right is 90 deg clockwise of it, down is -up.
  const double h = heading_deg * M_PI / 180.0;
  const Eigen::Vector3d forward(std::cos(h), std::sin(h), 0.0),
      right(std::sin(h), -std::cos(h), 0.0), down(0.0, 0.0, -1.0);
  Eigen::Isometry3d T_enu_kw = Eigen::Isometry3d::Identity();
  T_enu_kw.linear() << right, down, forward;
  const Eigen::Isometry3d T_c0_b = kittiCamFromImu();
  Trajectory out;
  out.t_ns = T_kw_c0.t_ns;
  out.poses.reserve(T_kw_c0.size());
  for (const auto& T : T_kw_c0.poses) {
    Eigen::Isometry3d T_enu_b = T_enu_kw * T * T_c0_b;
    // KITTI's rotations carry 7 significant digits: re-orthonormalise before the spline fit.
    T_enu_b.linear() = Eigen::Quaterniond(T_enu_b.rotation()).normalized().toRotationMatrix();
    out.poses.push_back(T_enu_b);
  }
  return out;
}

}  // namespace gvio::sim
