#include "fuzz/checks.hpp"

#include <cmath>
#include <string>

#include "fuzz/harness.hpp"
#include "io/dataset_sources.hpp"

namespace gvio::fuzz {

namespace {

bool finite(const Eigen::Isometry3d& T) {
  return T.matrix().allFinite();
}

// `tolerance`: 1e-6 where gvio builds the rotation; 1e-3 for a KITTI pose file's R, which gvio
// eval uses as written, as evo does (io/trajectory_io.cpp kRotationTolerance).
bool rotation(const Eigen::Matrix3d& R, double tolerance = 1e-6) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tolerance &&
         std::abs(R.determinant() - 1.0) <= 3.0 * tolerance;
}

bool increasing(const std::vector<std::int64_t>& t_ns) {
  for (std::size_t i = 1; i < t_ns.size(); ++i)
    if (t_ns[i] <= t_ns[i - 1]) return false;
  return true;
}

}  // namespace

void checkTrajectory(const Trajectory& traj, bool strictly_increasing, double rotation_tolerance) {
  require(!traj.hasTimestamps() || traj.t_ns.size() == traj.poses.size(),
          "trajectory stamps and poses differ in count");
  for (const auto& T : traj.poses) {
    require(finite(T), "trajectory pose not finite");
    require(rotation(T.linear(), rotation_tolerance), "trajectory pose rotation not orthonormal");
  }
  if (strictly_increasing) require(increasing(traj.t_ns), "trajectory stamps not increasing");
}

void checkFixes(const std::vector<GnssFix>& fixes) {
  std::vector<std::int64_t> t;
  for (const GnssFix& f : fixes) {
    t.push_back(f.t_ns);
    require(std::isfinite(f.lat_deg) && std::abs(f.lat_deg) <= 90.0, "fix latitude out of range");
    require(std::isfinite(f.lon_deg) && std::abs(f.lon_deg) <= 180.0, "fix longitude out of range");
    require(std::isfinite(f.h_ellipsoid_m), "fix height not finite");
    require(std::isfinite(f.sigma_h_m) && f.sigma_h_m > 0.0, "fix sigma_h not positive");
    require(std::isfinite(f.sigma_v_m) && f.sigma_v_m > 0.0, "fix sigma_v not positive");
  }
  require(increasing(t), "fix stamps not increasing");
}

void checkImu(const std::vector<ImuSample>& imu) {
  std::vector<std::int64_t> t;
  for (const ImuSample& s : imu) {
    t.push_back(s.t_ns);
    require(s.acc_b_mps2.allFinite() && s.gyr_b_radps.allFinite(), "IMU sample not finite");
  }
  require(increasing(t), "IMU stamps not increasing");
}

void checkCamera(const CameraModel& c) {
  require(c.width_px > 0 && c.height_px > 0, "camera size not positive");
  require(std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) && std::isfinite(c.cy),
          "camera intrinsics not finite");
  for (double k : c.distortion) require(std::isfinite(k), "camera distortion not finite");
  require(finite(c.T_b_c) && rotation(c.T_b_c.linear()), "camera extrinsics not a rigid motion");
}

void checkImuNoise(const ImuNoise& n) {
  for (double v : {n.acc_noise_density, n.gyr_noise_density, n.acc_random_walk, n.gyr_random_walk})
    require(std::isfinite(v) && v > 0.0, "IMU noise not a positive number");
}

void checkDataset(const io::Dataset& ds) {
  for (const CameraModel& c : ds.cameras) checkCamera(c);
  std::vector<std::int64_t> t;
  for (const io::FrameRecord& f : ds.frames) {
    t.push_back(f.t_ns);
    require(f.image_paths.empty() || f.image_paths.size() == ds.cameras.size(),
            "frame image count differs from the cameras");
  }
  require(increasing(t), "frame stamps not increasing");
  checkImu(ds.imu);
  checkFixes(ds.gnss);
  if (ds.imu_noise) checkImuNoise(*ds.imu_noise);
  if (ds.groundtruth) checkTrajectory(*ds.groundtruth, true);
}

void readWholeDataset(const std::filesystem::path& dataset,
                      std::vector<std::filesystem::path> calib_files) {
  io::DatasetSources sources;
  sources.dataset = dataset;
  sources.calib_files = std::move(calib_files);
  const io::Dataset ds = io::openDataset(sources, io::ReaderConfig{});
  checkDataset(ds);
  for (std::size_t f = 0; f < ds.frames.size(); ++f) {
    for (std::size_t c = 0; c < ds.cameras.size(); ++c) {
      const cv::Mat image = io::loadFrameImage(ds, f, c);
      require(image.type() == CV_8UC1 && image.cols == ds.cameras[c].width_px &&
                  image.rows == ds.cameras[c].height_px,
              "image not 8-bit grey of the camera's size");
    }
  }
}

}  // namespace gvio::fuzz
