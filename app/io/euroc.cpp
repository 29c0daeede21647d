#include "io/euroc.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <cmath>

#include <fstream>
#include <map>
#include <sstream>

#include "fusion/gnss_screening.hpp"
#include "io/input_error.hpp"
#include "io/rotation_check.hpp"
#include "io/sensor_yaml.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

Eigen::Isometry3d yamlTransform(const YAML::Node& root, const fs::path& file) {
  if (!root["T_BS"]) return Eigen::Isometry3d::Identity();
  const auto data = yamlList<double>(root["T_BS"], "data", 16, file);
  const Eigen::Matrix4d m =
      Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(data.data());
  const auto R = calibrationRotation(m.topLeftCorner<3, 3>());
  if (!R || !m.topRightCorner<3, 1>().allFinite() ||
      m.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
    throw InputError(file, lineOf(root["T_BS"]), "'T_BS' is not a rigid transform");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = *R;
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

CameraModel readCameraYaml(const fs::path& file, const std::string& name) {
  const YAML::Node y = loadSensorYaml(file);
  const std::string model = y["camera_model"] ? y["camera_model"].Scalar() : "pinhole";
  const std::string dist =
      y["distortion_model"] ? y["distortion_model"].Scalar() : "radial-tangential";
  // TUM VI ships its fisheye rigs in this layout with the equidistant (Kannala-Brandt) model.
  const bool equidistant = dist == "equidistant";
  if (model != "pinhole" || (dist != "radial-tangential" && dist != "radtan" && !equidistant)) {
    throw InputError(file, lineOf(y["distortion_model"] ? y["distortion_model"] : y),
                     fmt::format("unsupported camera model '{}' / '{}' (pinhole with "
                                 "radial-tangential or equidistant distortion)",
                                 model, dist));
  }
  CameraModel cam = pinholeCamera(y, name, file);
  cam.distortion = yamlList<double>(y, "distortion_coefficients", 4, file);
  if (equidistant) cam.distortion_model = Distortion::kEquidistant;
  cam.T_b_c = yamlTransform(y, file);
  return cam;
}

// A CSV of "t_ns,..." rows with `fields` columns and strictly increasing stamps; calls `row` for
// each data line.
template <typename Fn>
void readStampedCsv(const fs::path& file, std::size_t fields, Fn&& row) {
  LineReader reader(file);
  std::string line;
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  while (reader.next(line)) {
    if (isBlankOrComment(line)) continue;
    const auto f = splitDelimited(line, ',');
    if (f.size() != fields)
      reader.fail(fmt::format("expected {} fields, got {}", fields, f.size()));
    const std::int64_t t_ns = parseInt64(f[0], reader, "timestamp [ns]");
    if (t_ns <= last)
      reader.fail(t_ns == last ? "duplicate timestamp" : "timestamp not increasing");
    last = t_ns;
    row(t_ns, f, reader);
  }
}

void readImu(const fs::path& dir, Dataset& ds) {
  const fs::path yaml = dir / "sensor.yaml";
  if (fs::is_regular_file(yaml)) {
    const YAML::Node y = loadSensorYaml(yaml);
    ImuNoise n;
    // Each density must be stated, finite and positive: the estimator weighs every IMU residual
    // by it, so the file's own line is named here, not a config key later.
    auto get = [&](const char* key) {
      if (!y[key]) throw InputError(yaml, 0, fmt::format("missing '{}'", key));
      const auto line = static_cast<std::size_t>(y[key].Mark().line + 1);
      double v = 0.0;
      try {
        v = y[key].as<double>();
      } catch (const YAML::Exception&) {
        throw InputError(yaml, line, fmt::format("'{}' must be a number", key));
      }
      if (!std::isfinite(v) || v <= 0.0)
        throw InputError(yaml, line,
                         fmt::format("'{}' must be a positive number (got {})", key, v));
      return v;
    };
    n.gyr_noise_density = get("gyroscope_noise_density");
    n.gyr_random_walk = get("gyroscope_random_walk");
    n.acc_noise_density = get("accelerometer_noise_density");
    n.acc_random_walk = get("accelerometer_random_walk");
    ds.imu_noise = n;
  }
  readStampedCsv(dir / "data.csv", 7, [&](std::int64_t t_ns, const auto& f, const LineReader& at) {
    ImuSample s;
    s.t_ns = t_ns;
    for (int i = 0; i < 3; ++i) {
      s.gyr_b_radps[i] = parseFinite(f[1 + i], at, "angular rate");
      s.acc_b_mps2[i] = parseFinite(f[4 + i], at, "acceleration");
    }
    ds.imu.push_back(s);
  });
}

}  // namespace

std::vector<GnssFix> readGnssCsv(const fs::path& file, std::vector<std::string>& warnings) {
  std::vector<GnssFix> fixes;
  std::size_t skipped = 0, first_skipped_line = 0;
  readStampedCsv(file, 6, [&](std::int64_t t_ns, const auto& f, const LineReader& at) {
    GnssFix fix;
    fix.t_ns = t_ns;
    fix.lat_deg = parseFinite(f[1], at, "latitude");
    fix.lon_deg = parseFinite(f[2], at, "longitude");
    fix.h_ellipsoid_m = parseFinite(f[3], at, "height");
    fix.sigma_h_m = parseFinite(f[4], at, "sigma_h");
    fix.sigma_v_m = parseFinite(f[5], at, "sigma_v");
    if (fusion::latLonOutOfRange(fix.lat_deg, fix.lon_deg) || fix.sigma_h_m <= 0.0 ||
        fix.sigma_v_m <= 0.0) {
      if (skipped++ == 0) first_skipped_line = at.lineNumber();
      return;
    }
    fixes.push_back(fix);
  });
  if (skipped > 0) {
    warnings.push_back(fmt::format(
        "{}: {} fixes with lat/lon out of range or non-positive sigma skipped (first at line {})",
        file.string(), skipped, first_skipped_line));
  }
  return fixes;
}

namespace {

void readGnss(const fs::path& dir, Dataset& ds) {
  const fs::path file = dir / "data.csv";
  ds.gnss = readGnssCsv(file, ds.warnings);
  ds.gnss_source = file.string();
}

// stamp -> image path for one camera; listed images whose file is missing are dropped with one
// warning (the real EuRoC V1_01 cam1/data.csv lists stamps without images).
std::map<std::int64_t, fs::path> readCameraList(const fs::path& dir, Dataset& ds) {
  std::map<std::int64_t, fs::path> images;
  std::size_t missing = 0, first_missing_line = 0;
  readStampedCsv(dir / "data.csv", 2, [&](std::int64_t t_ns, const auto& f, const LineReader& at) {
    const fs::path image = dir / "data" / std::string(f[1]);
    // A name the file system cannot hold (too long, say) names no file either: missing, not an
    // exception (fuzzing found a 400-byte name that made status() throw ENAMETOOLONG).
    std::error_code ec;
    if (!fs::is_regular_file(image, ec)) {
      if (missing++ == 0) first_missing_line = at.lineNumber();
      return;
    }
    images.emplace(t_ns, image);
  });
  if (missing > 0) {
    ds.warnings.push_back(
        fmt::format("{}: {} listed images not found, frames skipped (first at line {})",
                    (dir / "data.csv").string(), missing, first_missing_line));
  }
  return images;
}

void readCameras(const fs::path& mav0, const Eigen::Isometry3d& T_BS_imu, Dataset& ds) {
  std::vector<std::map<std::int64_t, fs::path>> lists;
  for (const char* name : {"cam0", "cam1"}) {
    const fs::path dir = mav0 / name;
    if (!fs::is_directory(dir)) break;  // cam1 without cam0 is not a camera setup we know
    CameraModel cam =
        readingYaml(dir / "sensor.yaml", [&] { return readCameraYaml(dir / "sensor.yaml", name); });
    cam.T_b_c = T_BS_imu.inverse() * cam.T_b_c;  // body = IMU frame
    ds.cameras.push_back(cam);
    lists.push_back(readCameraList(dir, ds));
  }
  if (lists.empty()) return;
  std::size_t unpaired = 0;
  for (const auto& [t_ns, path0] : lists[0]) {
    FrameRecord frame{t_ns, {path0}};
    for (std::size_t k = 1; k < lists.size(); ++k) {
      const auto it = lists[k].find(t_ns);
      if (it == lists[k].end()) break;
      frame.image_paths.push_back(it->second);
    }
    if (frame.image_paths.size() == lists.size()) {
      ds.frames.push_back(std::move(frame));
    } else {
      ++unpaired;
    }
  }
  if (unpaired > 0) {
    ds.warnings.push_back(
        fmt::format("{}: {} cam0 frames have no cam1 image with the same stamp, skipped",
                    mav0.string(), unpaired));
  }
}

}  // namespace

fs::path findEurocMav0(const fs::path& path) {
  for (const auto& dir : {path / "mav0", path}) {
    if (fs::is_directory(dir / "cam0") || fs::is_directory(dir / "imu0") ||
        fs::is_directory(dir / "gnss0")) {
      return dir;
    }
  }
  return {};
}

Dataset readEuroc(const fs::path& path, const ReaderConfig& /*config*/) {
  if (!fs::is_directory(path)) throw InputError(path, 0, "dataset folder not found");
  const fs::path mav0 = findEurocMav0(path);
  if (mav0.empty())
    throw InputError(path, 0, "no mav0/ with cam0, imu0 or gnss0: not an EuRoC dataset");
  Dataset ds;
  ds.format = DatasetFormat::kEuroc;
  ds.root = path;
  ds.variant = "asl";
  Eigen::Isometry3d T_BS_imu = Eigen::Isometry3d::Identity();
  if (fs::is_directory(mav0 / "imu0")) {
    if (fs::is_regular_file(mav0 / "imu0" / "sensor.yaml")) {
      const fs::path yaml = mav0 / "imu0" / "sensor.yaml";
      T_BS_imu = readingYaml(yaml, [&] { return yamlTransform(loadSensorYaml(yaml), yaml); });
    }
    readingYaml(mav0 / "imu0" / "sensor.yaml", [&] { readImu(mav0 / "imu0", ds); });
  }
  readCameras(mav0, T_BS_imu, ds);
  std::vector<fs::path> calibration;
  for (std::size_t c = 0; c < ds.cameras.size(); ++c)
    calibration.push_back(mav0 / fmt::format("cam{}", c) / "sensor.yaml");
  checkFirstImageSizes(ds, calibration);
  if (fs::is_directory(mav0 / "gnss0")) readGnss(mav0 / "gnss0", ds);
  const fs::path gt = mav0 / "state_groundtruth_estimate0" / "data.csv";
  if (fs::is_regular_file(gt)) {
    ds.groundtruth = readEurocCsv(gt);
    ds.groundtruth_source = gt.string();
  }
  return ds;
}

}  // namespace gvio::io
