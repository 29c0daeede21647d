#include "io/dataset_sources.hpp"

#include <algorithm>

#include "io/gnss_file.hpp"
#include "io/input_error.hpp"
#include "io/kalibr.hpp"

namespace gvio::io {

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
  if (calibration) applyKalibr(ds, *calibration);
  if (ds.format == DatasetFormat::kRosbag && !ds.frames.empty() && ds.cameras.front().fx <= 0.0) {
    const InputError missing(ds.root, 0,
                             "a bag holds no camera calibration: give --calib camchain.yaml "
                             "[imu.yaml] (Kalibr)");
    if (sources.require_calibration) throw missing;
    ds.warnings.emplace_back(missing.what());
  }
  if (sources.gnss_file) useGnssFile(ds, *sources.gnss_file, config);
  return ds;
}

}  // namespace gvio::io
