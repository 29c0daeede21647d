#pragma once
// gvio run's map stage: keyframes go into a mapping::MapBuilder while the VIO runs (their dense
// stereo points and landmarks in their own frames); after GNSS fusion the map is built from the
// final poses (T_enu_b when fused, else the VIO poses) and written as map.pcd, map.ply (the
// merged sparse + dense cloud, float32), map.las when the run is georeferenced (the same cloud in
// UTM, as `gvio export --to las` writes it) and map.bt / map.ot (OctoMap OcTree / ColorOcTree).
#include <filesystem>
#include <functional>
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
  // The map's two build stages (mapping::MapBuilder::buildClouds, buildOccupancyReleasing, which
  // frees the keyframes' dense points): take every other look at the keyframes (e.g. --two-pass)
  // before the second.
  [[nodiscard]] mapping::MapBuildResult buildClouds(const mapping::PoseLookup& pose_of) const {
    return builder_->buildClouds(pose_of);
  }
  void buildOccupancyReleasing(const mapping::PoseLookup& pose_of, mapping::MapBuildResult& into) {
    builder_->buildOccupancyReleasing(pose_of, into);
  }
  // The occupancy without freeing (safe beside the const looks above on another thread), and the
  // freeing afterwards.
  void buildOccupancy(const mapping::PoseLookup& pose_of, mapping::MapBuildResult& into) const {
    builder_->buildOccupancy(pose_of, into);
  }
  void releaseDense() { builder_->releaseDense(); }
  [[nodiscard]] const std::vector<mapping::KeyframeTimings>& timings() const { return timings_; }

 private:
  mapping::MapConfig config_;
  std::unique_ptr<mapping::MapBuilder> builder_;
  std::vector<mapping::KeyframeTimings> timings_;
};

struct MapRunResult {
  mapping::MapBuildResult map;  // counts and timings; the clouds and trees are freed once written
  std::string frame;            // "enu" (GNSS-fused poses) or "vio_world"
  double build_ms = 0.0;        // both build stages, without the writing
  nlohmann::json las;           // report.json's map "las": written, file, points, CRS, or why not
};

// Where the map's poses come from: the final trajectory (fused and/or loop-closed) when not null
// and not empty, else the VIO's; and how late the images' stamps are against their exposures
// (the camera-IMU time offset t_d the VIO estimated, s; 0 when it did not).
struct MapPoseSource {
  const Trajectory* fused = nullptr;
  const Trajectory* vio = nullptr;
  double exposure_lag_s = 0.0;
};

// The poses the map is built with, the body's at each keyframe's exposure: the fused trajectory's
// (T_enu_b) when there is one, else the VIO's (T_w_b), interpolated at the keyframe's stamp less
// exposure_lag_s (at the stamp itself where that falls outside the trajectory). Without a lag:
// the fused trajectory at the stamps, else the keyframes' own VIO poses. Refers to `recorder` and
// the trajectories: use it while they live.
mapping::PoseLookup mapPoses(const MapRecorder& recorder, const MapPoseSource& source);

// Builds the map with mapPoses() and writes it to `out`, each file atomically, in an order that
// bounds memory on a long drive: the clouds first (sparse landmarks + dense points, merged into
// map.pcd, binary compressed, and map.ply, binary, through PCL; and map.las), freed once written;
// then the occupancy, inserted while the keyframes' stored points are freed, written as map.bt
// (maximum-likelihood OcTree) and map.ot (ColorOcTree). map.las (LAS 1.4 in UTM + ellipsoidal
// height, through the run's georef.json with exporter::writeMapLas, the function behind
// `gvio export --to las`) only when the map is in ENU (the run is georeferenced: georef.json
// written); otherwise the reason is logged and a map.las of an earlier run in `out` is removed.
// An empty cloud writes no cloud files and warns.
// `georeferenced`: `fused` is in local ENU (else the VIO world, e.g. loop-closed without GNSS).
// `alongside`: read-only looks at the keyframes (revisits, --two-pass) that need their dense
// points; it runs first. `threaded`: the occupancy is built on a thread of its own while the
// cloud files are written (nothing freed until it is done); the files are the same either way.
MapRunResult buildAndWriteMap(MapRecorder& recorder, const MapPoseSource& source,
                              bool georeferenced, const std::filesystem::path& out,
                              bool threaded = false, const std::function<void()>& alongside = {});

// report.json's "map": frame, counts, per-keyframe cost of each stage (ms mean/p95/max), memory.
nlohmann::json mapReport(const MapRecorder& recorder, const MapRunResult& result);

}  // namespace gvio::run
