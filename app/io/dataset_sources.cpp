#include "io/dataset_sources.hpp"

#include <algorithm>

#include "io/gnss_file.hpp"
#include "io/input_error.hpp"
#include "io/kalibr.hpp"

namespace gvio::io {

namespace {

// Kalibr replaced the cameras: what the recording said of them no longer applies.
void useKalibrSources(Dataset& ds, const std::vector<std::filesystem::path>& files) {
  std::string names;
  for (const auto& f : files) names += (names.empty() ? "" : " + ") + f.string();
  std::erase_if(ds.calibration_sources,
                [](const CalibrationSource& c) { return c.value != "GNSS lever arm"; });
  for (const CameraModel& cam : ds.cameras) {
    ds.calibration_sources.push_back({cam.name + " intrinsics", "--calib " + names});
    ds.calibration_sources.push_back({"T_b_" + cam.name, "--calib " + names});
  }
  ds.calibration_missing.clear();
}

}  // namespace

Dataset openDataset(const DatasetSources& sources, ReaderConfig config) {
  std::optional<KalibrCalibration> calibration;
  if (!sources.calib_files.empty()) {
    calibration = readKalibr(sources.calib_files);
    const auto& topics = calibration->camera_topics;
    const bool all_named =
        !topics.empty() && std::find(topics.begin(), topics.end(), std::string()) == topics.end();
    if (config.topic_cam0.empty() && all_named && topics.size() <= 2) {
      config.topic_cam0 = topics[0];
      if (topics.size() == 2) config.topic_cam1 = topics[1];
    }
    if (config.topic_imu.empty()) config.topic_imu = calibration->imu_topic;
  }
  Dataset ds = readDataset(sources.dataset, sources.format, config);
  if (calibration) {
    applyKalibr(ds, *calibration);
    if (!calibration->cameras.empty()) useKalibrSources(ds, sources.calib_files);
  }
  const bool bag = ds.format == DatasetFormat::kRosbag || ds.format == DatasetFormat::kRos2Bag;
  if (bag && !ds.frames.empty() && ds.cameras.front().fx <= 0.0) {
    const InputError missing(
        ds.root, 0,
        ds.format == DatasetFormat::kRosbag
            ? "a bag holds no camera calibration: give --calib camchain.yaml [imu.yaml] (Kalibr)"
            : "the bag does not calibrate its cameras (" + ds.calibration_missing +
                  "): record CameraInfo and /tf_static, or give --calib camchain.yaml [imu.yaml] "
                  "(Kalibr)");
    if (sources.require_calibration) throw missing;
    ds.warnings.emplace_back(missing.what());
  }
  if (sources.gnss_file) useGnssFile(ds, *sources.gnss_file, config);
  if (config.gnss_ellipse == "circle") {
    for (GnssFix& fix : ds.gnss) fix.shape_en.setIdentity();
  }
  return ds;
}

}  // namespace gvio::io
