#pragma once
// gvio run's map stage: keyframes go into a mapping::MapBuilder while the VIO runs (their dense
// stereo points and landmarks in their own frames); after GNSS fusion the map is built from the
// final poses (T_enu_b when fused, else the VIO poses) and written as map.pcd, map.ply (the merged
// sparse + dense cloud, float32), map.bt / map.ot (OctoMap OcTree / ColorOcTree) and, when the run
// is georeferenced, map.las (the same cloud in UTM, as `gvio export --to las` writes it).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mapping/map_builder.hpp"
#include "odometry/trajectory.hpp"
#include "run/vio_runner.hpp"

namespace gvio::run {

class MapRecorder {
 public:
  explicit MapRecorder(const mapping::MapConfig& config);

  // The runVio keyframe hook: the builder is made at the first keyframe (the rectified camera is
  // known only then).
  void addKeyframe(const KeyframeInput& keyframe);

  [[nodiscard]] bool empty() const { return !builder_; }
  [[nodiscard]] const mapping::MapBuilder& builder() const { return *builder_; }
  // The map, freeing the stored dense points as they go in (mapping::MapBuilder::buildReleasing):
  // take every other look at the keyframes (e.g. --two-pass) before.
  [[nodiscard]] mapping::MapBuildResult buildReleasing(const mapping::PoseLookup& pose_of) {
    return builder_->buildReleasing(pose_of);
  }
  [[nodiscard]] const std::vector<mapping::KeyframeTimings>& timings() const { return timings_; }

 private:
  mapping::MapConfig config_;
  std::unique_ptr<mapping::MapBuilder> builder_;
  std::vector<mapping::KeyframeTimings> timings_;
};

struct MapRunResult {
  mapping::MapBuildResult map;
  std::string frame;  // "enu" (GNSS-fused poses) or "vio_world"
  double build_ms = 0.0;
};

// The poses the map is built with: the fused trajectory's (T_enu_b, interpolated at the keyframe
// stamps) when `fused` is given and not empty, else the keyframes' VIO poses (T_w_b). Refers to
// `recorder` and `fused`: use it while they live.
mapping::PoseLookup mapPoses(const MapRecorder& recorder, const Trajectory* fused);

// Builds the map with the fused trajectory's poses (interpolated at the keyframe stamps) when
// `fused` is given and not empty, else with the keyframes' VIO poses.
// Frees the recorder's dense points as they go into the map (MapRecorder::buildReleasing).
MapRunResult buildMap(MapRecorder& recorder, const Trajectory* fused);

// map.bt, map.ot, map.pcd (binary compressed), map.ply (binary) and map.las, each atomically.
// map.las (LAS 1.4 in UTM + ellipsoidal height, through the run's georef.json with
// exporter::writeMapLas, the function behind `gvio export --to las`) only when the map is in ENU
// (the run is georeferenced: georef.json written); otherwise the reason is logged and a map.las
// of an earlier run in `out` is removed. An empty map writes no cloud files and warns.
// Consumes the result's trees and dense cloud (each is freed once written, so a long drive's map
// is not held twice); the counts stay. Returns report.json's map "las": written, and the file,
// points and CRS, or the reason.
nlohmann::json writeMapFiles(const std::filesystem::path& out, MapRunResult& result);

// report.json's "map": frame, counts, per-keyframe cost of each stage (ms mean/p95/max), memory.
nlohmann::json mapReport(const MapRecorder& recorder, const MapRunResult& result);

}  // namespace gvio::run
