#include "io/kitti_calib.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/input_error.hpp"
#include "io/rotation_check.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

Eigen::Isometry3d isometryFrom(const std::vector<double>& R9, const std::vector<double>& t3) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R9.data());
  T.translation() = Eigen::Vector3d(t3[0], t3[1], t3[2]);
  return T;
}

// Rotation matrices in the calibration must be proper rotations; a typo there silently corrupts
// every projection otherwise. KITTI prints them to 7 digits: they are made exactly orthonormal.
Eigen::Matrix3d requireRotation(const Eigen::Matrix3d& R, const KittiCalibFile& file,
                                const std::string& key) {
  const auto rotation = calibrationRotation(R);
  if (!rotation) throw InputError(file.path(), 0, key + " is not a rotation matrix");
  return *rotation;
}

void requireImageSize(const CameraModel& cam, const KittiCalibFile& file, const std::string& key) {
  if (cam.width_px < 1 || cam.height_px < 1 || cam.width_px > 100000 || cam.height_px > 100000) {
    throw InputError(file.path(), 0, key + " is not an image size");
  }
}

Eigen::Isometry3d readRt(const KittiCalibFile& file, const std::string& r_key,
                         const std::string& t_key) {
  Eigen::Isometry3d T = isometryFrom(file.numbers(r_key, 9), file.numbers(t_key, 3));
  T.linear() = requireRotation(T.linear(), file, r_key);
  return T;
}

// A pinhole camera matrix [fx s cx; 0 fy cy; 0 0 1] (row-major, `stride` 3 for K, 4 for P): its
// last row fixed, so the matrix is invertible and the projection homogeneous (a zeroed last row
// would divide by zero in every projection).
void requireCameraMatrix(const std::vector<double>& m, std::size_t stride,
                         const KittiCalibFile& c2c, const std::string& key) {
  const auto at = [&](std::size_t r, std::size_t c) { return m[r * stride + c]; };
  const bool ok = at(0, 0) > 0.0 && at(1, 1) > 0.0 && at(1, 0) == 0.0 && at(2, 0) == 0.0 &&
                  at(2, 1) == 0.0 && std::abs(at(2, 2) - 1.0) < 1e-9;
  if (!ok) {
    throw InputError(c2c.path(), c2c.lineOf(key),
                     key +
                         " is not a camera matrix (expected fx > 0, fy > 0 and rows 2-3 "
                         "0 fy cy / 0 0 1)");
  }
}

CameraModel rectifiedCamera(const KittiCalibFile& c2c, int id) {
  const auto S = c2c.numbers(fmt::format("S_rect_{:02d}", id), 2);
  const auto P = c2c.numbers(fmt::format("P_rect_{:02d}", id), 12);
  const auto R_rect = c2c.numbers("R_rect_00", 9);
  CameraModel cam;
  cam.width_px = static_cast<int>(std::lround(S[0]));
  cam.height_px = static_cast<int>(std::lround(S[1]));
  cam.fx = P[0];
  cam.fy = P[5];
  cam.cx = P[2];
  cam.cy = P[6];
  // P_rect = K_rect [I | t]: the 4th column is K_rect t (devkit readme, "P_rect_xx").
  requireCameraMatrix(P, 4, c2c, fmt::format("P_rect_{:02d}", id));
  Eigen::Matrix3d K;
  K << P[0], P[1], P[2], P[4], P[5], P[6], P[8], P[9], P[10];
  const Eigen::Vector3d t = K.inverse() * Eigen::Vector3d(P[3], P[7], P[11]);
  Eigen::Isometry3d T_ci_cam0 = Eigen::Isometry3d::Identity();
  T_ci_cam0.linear() =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_rect.data());
  T_ci_cam0.linear() = requireRotation(T_ci_cam0.linear(), c2c, "R_rect_00");
  if (!(cam.fx > 0.0 && cam.fy > 0.0) || !t.allFinite()) {
    throw InputError(c2c.path(), 0, fmt::format("P_rect_{:02d} is not a camera matrix", id));
  }
  requireImageSize(cam, c2c, fmt::format("S_rect_{:02d}", id));
  T_ci_cam0.pretranslate(t);
  cam.T_b_c = T_ci_cam0;  // completed by the caller with the cam0 <- IMU chain
  return cam;
}

CameraModel rawCamera(const KittiCalibFile& c2c, int id) {
  const auto S = c2c.numbers(fmt::format("S_{:02d}", id), 2);
  const auto K = c2c.numbers(fmt::format("K_{:02d}", id), 9);
  CameraModel cam;
  cam.width_px = static_cast<int>(std::lround(S[0]));
  cam.height_px = static_cast<int>(std::lround(S[1]));
  cam.fx = K[0];
  cam.fy = K[4];
  cam.cx = K[2];
  cam.cy = K[5];
  cam.distortion = c2c.numbers(fmt::format("D_{:02d}", id), 5);
  requireCameraMatrix(K, 3, c2c, fmt::format("K_{:02d}", id));
  requireImageSize(cam, c2c, fmt::format("S_{:02d}", id));
  cam.T_b_c = readRt(c2c, fmt::format("R_{:02d}", id), fmt::format("T_{:02d}", id));
  return cam;
}

std::filesystem::path findOne(const std::filesystem::path& drive_dir, const char* name) {
  for (const auto& dir : {drive_dir, drive_dir.parent_path()}) {
    if (std::filesystem::is_regular_file(dir / name)) return dir / name;
  }
  throw InputError(drive_dir / name, 0, "calibration file not found here nor in the parent folder");
}

}  // namespace

std::size_t KittiCalibFile::lineOf(const std::string& key) const {
  const auto it = entries_.find(key);
  return it == entries_.end() ? 0 : it->second.line;
}

KittiCalibFile::KittiCalibFile(const std::filesystem::path& file) : path_(file) {
  LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (isBlankOrComment(line)) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) reader.fail("expected 'key: values'");
    const std::string key(trim(std::string_view(line).substr(0, colon)));
    entries_[key] =
        Entry{std::string(trim(std::string_view(line).substr(colon + 1))), reader.lineNumber()};
  }
}

std::vector<double> KittiCalibFile::numbers(const std::string& key, std::size_t count) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) throw InputError(path_, 0, "missing key '" + key + "'");
  const auto fields = splitWhitespace(it->second.text);
  if (fields.size() != count) {
    throw InputError(path_, it->second.line,
                     fmt::format("{} has {} values, expected {}", key, fields.size(), count));
  }
  std::vector<double> values;
  values.reserve(count);
  for (const auto& f : fields) {
    char* end = nullptr;
    const std::string token(f);
    const double v = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size() || !std::isfinite(v)) {
      throw InputError(path_, it->second.line, fmt::format("{}: malformed value '{}'", key, token));
    }
    values.push_back(v);
  }
  return values;
}

KittiCalibPaths findKittiCalib(const std::filesystem::path& drive_dir) {
  return {findOne(drive_dir, "calib_cam_to_cam.txt"), findOne(drive_dir, "calib_imu_to_velo.txt"),
          findOne(drive_dir, "calib_velo_to_cam.txt")};
}

std::vector<CameraModel> readKittiCameras(const KittiCalibPaths& paths, const std::vector<int>& ids,
                                          bool rectified) {
  const KittiCalibFile c2c(paths.cam_to_cam);
  const KittiCalibFile i2v(paths.imu_to_velo);
  const KittiCalibFile v2c(paths.velo_to_cam);
  const Eigen::Isometry3d T_velo_imu = readRt(i2v, "R", "T");
  const Eigen::Isometry3d T_cam0_velo = readRt(v2c, "R", "T");
  std::vector<CameraModel> cameras;
  for (const int id : ids) {
    CameraModel cam = rectified ? rectifiedCamera(c2c, id) : rawCamera(c2c, id);
    cam.name = fmt::format("image_{:02d}", id);
    const Eigen::Isometry3d T_ci_imu = cam.T_b_c * T_cam0_velo * T_velo_imu;
    cam.T_b_c = T_ci_imu.inverse();
    if (cam.width_px <= 0 || cam.height_px <= 0 || cam.fx <= 0.0 || cam.fy <= 0.0) {
      throw InputError(paths.cam_to_cam, 0,
                       cam.name + ": image size and focal length must be positive");
    }
    cameras.push_back(std::move(cam));
  }
  return cameras;
}

}  // namespace gvio::io
