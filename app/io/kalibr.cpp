#include "io/kalibr.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>

#include "io/input_error.hpp"
#include "io/sensor_yaml.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;

Eigen::Isometry3d transform4x4(const YAML::Node& block, const char* key, const fs::path& file) {
  const YAML::Node rows = block[key];
  if (!rows || !rows.IsSequence() || rows.size() != 4) {
    throw InputError(file, lineOf(rows ? rows : block),
                     fmt::format("'{}' must be a 4x4 matrix (four rows of four numbers)", key));
  }
  Eigen::Matrix4d m;
  for (std::size_t r = 0; r < 4; ++r) {
    YAML::Node row_holder;
    row_holder["row"] = rows[r];
    const auto row = yamlList<double>(row_holder, "row", 4, file);
    for (std::size_t c = 0; c < 4; ++c) m(static_cast<int>(r), static_cast<int>(c)) = row[c];
  }
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!m.allFinite() || ortho > 1e-6 || R.determinant() <= 0.0 ||
      (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12) {
    throw InputError(file, lineOf(rows), fmt::format("'{}' is not a rigid transform", key));
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = m;
  return T;
}

std::string scalar(const YAML::Node& block, const char* key, const fs::path& file) {
  const YAML::Node node = block[key];
  if (!node || !node.IsScalar()) {
    throw InputError(file, lineOf(block), fmt::format("missing '{}'", key));
  }
  return node.Scalar();
}

double number(const YAML::Node& block, const char* key, const fs::path& file) {
  const std::string text = scalar(block, key, file);
  try {
    const double v = block[key].as<double>();
    if (std::isfinite(v)) return v;
  } catch (const YAML::Exception&) {
  }
  throw InputError(file, lineOf(block[key]),
                   fmt::format("'{}' must be a number, not '{}'", key, text));
}

// One camN block. `previous`: T_cam_imu of camN-1, for T_cn_cnm1.
Eigen::Isometry3d readCamera(const YAML::Node& block, const std::string& name,
                             const std::optional<Eigen::Isometry3d>& previous, const fs::path& file,
                             KalibrCalibration& out) {
  const std::string model = scalar(block, "camera_model", file);
  const std::string distortion = scalar(block, "distortion_model", file);
  if (model != "pinhole") {
    throw InputError(
        file, lineOf(block["camera_model"]),
        fmt::format("{}: camera_model '{}' is not supported (pinhole only)", name, model));
  }
  if (distortion == "fov") {
    throw InputError(file, lineOf(block["distortion_model"]),
                     fmt::format("{}: distortion_model 'fov' is not supported yet (radtan and "
                                 "equidistant only): FOV-model rectification is not built",
                                 name));
  }
  if (distortion != "radtan" && distortion != "equidistant" && distortion != "none") {
    throw InputError(file, lineOf(block["distortion_model"]),
                     fmt::format("{}: unknown distortion_model '{}'", name, distortion));
  }
  CameraModel cam = pinholeCamera(block, name, file);
  if (distortion != "none") {
    // radtan: k1 k2 p1 p2; equidistant: Kannala-Brandt k1 k2 k3 k4, cv::fisheye's order too.
    cam.distortion = yamlList<double>(block, "distortion_coeffs", 4, file);
  }
  if (distortion == "equidistant") cam.distortion_model = Distortion::kEquidistant;
  Eigen::Isometry3d T_cam_imu;
  if (block["T_cam_imu"]) {
    T_cam_imu = transform4x4(block, "T_cam_imu", file);
    if (previous && block["T_cn_cnm1"]) {  // both: they must tell the same story
      const Eigen::Isometry3d chained = transform4x4(block, "T_cn_cnm1", file) * *previous;
      const Eigen::Isometry3d diff = chained.inverse() * T_cam_imu;
      const double deg = Eigen::AngleAxisd(diff.rotation()).angle() * 180.0 / M_PI;
      if (diff.translation().norm() > 1e-3 || deg > 0.05) {
        out.warnings.push_back(fmt::format(
            "{}: {}: T_cn_cnm1 and T_cam_imu disagree by {:.4f} m / {:.3f} deg; T_cam_imu is used",
            file.string(), name, diff.translation().norm(), deg));
      }
    }
  } else if (previous && block["T_cn_cnm1"]) {
    T_cam_imu = transform4x4(block, "T_cn_cnm1", file) * *previous;
  } else {
    throw InputError(file, lineOf(block), name + ": missing 'T_cam_imu'");
  }
  cam.T_b_c = T_cam_imu.inverse();
  out.cameras.push_back(cam);
  return T_cam_imu;
}

ImuNoise readImuNoise(const YAML::Node& block, const fs::path& file) {
  ImuNoise n;
  n.acc_noise_density = number(block, "accelerometer_noise_density", file);
  n.acc_random_walk = number(block, "accelerometer_random_walk", file);
  n.gyr_noise_density = number(block, "gyroscope_noise_density", file);
  n.gyr_random_walk = number(block, "gyroscope_random_walk", file);
  try {
    n.validate();
  } catch (const InvalidInput& e) {
    throw InputError(file, lineOf(block), e.what());
  }
  return n;
}

// One Kalibr file: a camera chain, an IMU file, or both.
void readKalibrFile(const fs::path& file, KalibrCalibration& out) {
  const YAML::Node root = loadSensorYaml(file);
  bool used = false;
  std::optional<Eigen::Isometry3d> previous;
  for (int i = 0; root["cam" + std::to_string(i)]; ++i) {
    if (!out.cameras.empty() && i == 0) {
      throw InputError(file, 0, "a second camera chain: give one camchain file");
    }
    const std::string name = "cam" + std::to_string(i);
    const YAML::Node block = root[name];
    previous = readCamera(block, name, previous, file, out);
    out.camera_topics.push_back(block["rostopic"] ? scalar(block, "rostopic", file) : "");
    const double shift =
        block["timeshift_cam_imu"] ? number(block, "timeshift_cam_imu", file) : 0.0;
    // Clock offsets are milliseconds; seconds would mean another time scale, and the stamps it
    // shifts must stay within int64 nanoseconds.
    if (!(std::abs(shift) <= 1.0)) {
      throw InputError(file, lineOf(block["timeshift_cam_imu"]),
                       fmt::format("{}: timeshift_cam_imu {} s is not a camera-IMU clock offset "
                                   "(expected within +-1 s)",
                                   name, shift));
    }
    if (i == 0) {
      out.timeshift_cam_imu_s = shift;
    } else if (std::abs(shift - out.timeshift_cam_imu_s) > 1e-6) {
      out.warnings.push_back(
          fmt::format("{}: {} timeshift_cam_imu {} s differs from cam0's {} s; "
                      "cam0's is used for every camera",
                      file.string(), name, shift, out.timeshift_cam_imu_s));
    }
    used = true;
  }
  const YAML::Node imu = root["imu0"] ? root["imu0"] : root;
  if (imu["accelerometer_noise_density"] || imu["gyroscope_noise_density"]) {
    out.imu_noise = readImuNoise(imu, file);
    if (imu["rostopic"]) out.imu_topic = scalar(imu, "rostopic", file);
    used = true;
  }
  if (!used) {
    throw InputError(file, 0,
                     "neither a Kalibr camera chain (cam0, cam1, ...) nor an IMU file "
                     "(accelerometer_noise_density, ...)");
  }
}

}  // namespace

KalibrCalibration readKalibr(const std::vector<fs::path>& files) {
  KalibrCalibration out;
  for (const fs::path& file : files) {
    readingYaml(file, [&] { readKalibrFile(file, out); });
  }
  return out;
}

void applyKalibr(Dataset& ds, const KalibrCalibration& c) {
  for (const std::string& w : c.warnings) ds.warnings.push_back(w);
  if (!c.cameras.empty()) {
    if (c.cameras.size() != ds.cameras.size()) {
      throw InvalidInput(fmt::format("--calib: the camera chain has {} camera(s), the dataset {}",
                                     c.cameras.size(), ds.cameras.size()));
    }
    for (std::size_t i = 0; i < c.cameras.size(); ++i) {
      const CameraModel& from_images = ds.cameras[i];
      const CameraModel& calibrated = c.cameras[i];
      if (from_images.fx == 0.0 && from_images.width_px > 0 &&
          (from_images.width_px != calibrated.width_px ||
           from_images.height_px != calibrated.height_px)) {
        throw InvalidInput(fmt::format(
            "--calib: {} is calibrated for {}x{} pixels, the dataset's images are {}x{}",
            calibrated.name, calibrated.width_px, calibrated.height_px, from_images.width_px,
            from_images.height_px));
      }
    }
    ds.cameras = c.cameras;
  }
  if (c.imu_noise) ds.imu_noise = c.imu_noise;
  const auto shift_ns = static_cast<std::int64_t>(std::llround(c.timeshift_cam_imu_s * 1e9));
  if (shift_ns != 0) {
    for (FrameRecord& f : ds.frames) f.t_ns += shift_ns;  // into the IMU's clock
  }
  ds.camera_timeshift_s = c.timeshift_cam_imu_s;
}

}  // namespace gvio::io
