#include "run/map_run.hpp"

#include <fmt/format.h>
#include <pcl/conversions.h>
#include <spdlog/spdlog.h>

#include <chrono>

#include "export/georef.hpp"
#include "export/map_files.hpp"
#include "fusion/vio_enu_alignment.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {

nlohmann::json timingJson(const std::vector<double>& ms) {
  const TimingSummary t = summarizeTimings(ms);
  return {{"mean", t.mean}, {"p95", t.p95}, {"max", t.max}, {"n", ms.size()}};
}

// OctoMap writes by file name: a temporary sibling with the same extension, then the rename.
// `binary`: the maximum-likelihood .bt of an OcTree; else the full .ot of any tree.
void writeTreeAtomic(const std::filesystem::path& file,
                     const octomap::AbstractOccupancyOcTree& tree, bool binary) {
  const std::filesystem::path tmp = io::temporarySibling(file, file.extension().string());
  const bool ok = binary ? tree.writeBinaryConst(tmp.string()) : tree.write(tmp.string());
  if (!ok) {
    std::filesystem::remove(tmp);
    throw io::InputError(file, 0, "cannot write the OctoMap file");
  }
  io::moveIntoPlace(tmp, file);
}

// The file map (sparse then dense points) as PCL's generic cloud; no data for an empty map.
pcl::PCLPointCloud2 mapBlob(const MapRunResult& r) {
  const mapping::MapCloud cloud = mapping::mergeMapClouds(r.map.sparse, r.map.dense);
  pcl::PCLPointCloud2 blob;
  if (!cloud.empty()) pcl::toPCLPointCloud2(cloud, blob);
  return blob;
}

}  // namespace

MapRecorder::MapRecorder(const mapping::MapConfig& config) : config_(config) {
  config_.validate();
}

void MapRecorder::addKeyframe(const KeyframeInput& kf) {
  if (!builder_) {
    builder_ = std::make_unique<mapping::MapBuilder>(config_, kf.left_camera, kf.baseline_m);
  }
  timings_.push_back(
      builder_->addKeyframe(kf.t_ns, kf.T_w_b, kf.left, kf.right, kf.estimator.landmarks()));
}

mapping::PoseLookup mapPoses(const MapRecorder& recorder, const Trajectory* fused) {
  if (fused == nullptr || fused->empty()) return recorder.builder().vioPoses();
  return [fused](std::int64_t t_ns) { return fusion::interpolatePose(*fused, t_ns); };
}

MapRunResult buildMap(const MapRecorder& recorder, const Trajectory* fused) {
  const auto start = std::chrono::steady_clock::now();
  MapRunResult r;
  r.frame = fused != nullptr && !fused->empty() ? "enu" : "vio_world";
  r.map = recorder.builder().build(mapPoses(recorder, fused));
  r.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return r;
}

void writeMapFiles(const std::filesystem::path& out, const MapRunResult& r) {
  const pcl::PCLPointCloud2 blob = mapBlob(r);
  if (blob.data.empty()) {
    spdlog::warn("the map is empty (no keyframe had landmarks or depth): no map files written");
    return;
  }
  exporter::writePcd(out / "map.pcd", blob);
  exporter::writePly(out / "map.ply", blob);
  if (r.map.occupancy) writeTreeAtomic(out / "map.bt", *r.map.occupancy, true);
  if (r.map.occupancy_color) writeTreeAtomic(out / "map.ot", *r.map.occupancy_color, false);
}

nlohmann::json writeMapLas(const std::filesystem::path& out, const MapRunResult& r) {
  const std::filesystem::path file = out / "map.las";
  const pcl::PCLPointCloud2 blob = r.frame == "enu" ? mapBlob(r) : pcl::PCLPointCloud2();
  if (blob.data.empty()) {
    const std::string reason =
        r.frame == "enu"
            ? "the map is empty"
            : "the run is not georeferenced (no GNSS fusion, or the VIO world was never "
              "registered to ENU: no georef.json), so the map is in the VIO world frame";
    spdlog::info("no map.las: {}", reason);
    std::error_code ec;
    if (std::filesystem::remove(file, ec)) {
      spdlog::info("removed {} of an earlier run", file.string());
    }
    return {{"written", false}, {"reason", reason}};
  }
  const exporter::Georef georef = exporter::readGeoref(out / "georef.json");
  const exporter::LasSummary s = exporter::writeMapLas(file, blob, georef, out / "map.pcd");
  return {{"written", true},
          {"file", "map.las"},
          {"points", s.points},
          {"crs", fmt::format("EPSG:{} (UTM zone {}{}) + ellipsoidal height", s.crs.epsg(),
                              s.crs.zone, s.crs.north ? "N" : "S")}};
}

nlohmann::json mapReport(const MapRecorder& recorder, const MapRunResult& r) {
  const mapping::MapCounts& c = r.map.counts;
  std::vector<double> sparse_ms, dense_ms;
  for (const auto& t : recorder.timings()) {
    sparse_ms.push_back(t.ms_sparse);
    if (t.ms_dense > 0.0) dense_ms.push_back(t.ms_dense);
  }
  return {{"frame", r.frame},
          {"keyframes", c.keyframes},
          {"keyframes_used", c.keyframes_used},
          {"keyframes_without_pose", c.keyframes_skipped},
          {"sparse_points", c.sparse_points},
          {"landmarks_stored", c.landmarks_stored},
          {"landmarks_rejected", c.landmarks_rejected},
          {"dense_points", c.dense_points},
          {"dense_points_before_filters", c.dense_points_raw},
          {"occupied_voxels", c.occupied_leaves},
          {"ms_per_keyframe",
           {{"sparse", timingJson(sparse_ms)},
            {"dense_depth", timingJson(dense_ms)},
            {"octomap", timingJson(r.map.ms_octomap_per_keyframe)}}},
          {"ms_dense_filters", r.map.ms_dense_fusion},
          {"ms_build", r.build_ms},
          {"store_mb", static_cast<double>(c.store_bytes) / 1e6},
          {"octree_mb", static_cast<double>(c.octree_bytes) / 1e6}};
}

}  // namespace gvio::run
