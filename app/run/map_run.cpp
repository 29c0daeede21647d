#include "run/map_run.hpp"

#include <fmt/format.h>
#include <pcl/conversions.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <future>

#include "export/georef.hpp"
#include "export/map_files.hpp"
#include "fusion/vio_enu_alignment.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/quiet_stderr.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {

nlohmann::json timingJson(const std::vector<double>& ms) {
  const TimingSummary t = summarizeTimings(ms);
  return {{"mean", t.mean}, {"p95", t.p95}, {"max", t.max}, {"n", ms.size()}};
}

// OctoMap's stream writers, through writeFileAtomic (which checks the stream): `binary`, the
// maximum-likelihood .bt of an OcTree; else the full .ot of any tree.
void writeTreeAtomic(const std::filesystem::path& file,
                     const octomap::AbstractOccupancyOcTree& tree, bool binary) {
  io::writeFileAtomic(file, [&](std::ostream& out) {
    const io::QuietStderr quiet;  // the map stage's threads are done by now
    if (!(binary ? tree.writeBinaryConst(out) : tree.write(out))) {
      throw io::InputError(file, 0, "OctoMap could not write the tree");
    }
  });
}

// The merged cloud (sparse landmarks first, then the dense points) as PCL's blob without a merged
// copy in between: the dense cloud is released as soon as its bytes are in the blob, so the map
// is held once. pcl::toPCLPointCloud2 copies the point structs byte for byte (it sets point_step
// = sizeof(MapPoint) and the fields' offsets in the struct), which is what is done here for the
// two clouds one after the other; the header (fields, point_step) comes from an empty cloud.
pcl::PCLPointCloud2 mapBlob(const mapping::MapCloud& sparse, mapping::MapCloud& dense) {
  pcl::PCLPointCloud2 blob;
  pcl::toPCLPointCloud2(mapping::MapCloud{}, blob);
  const std::size_t n = sparse.size() + dense.size();
  blob.width = static_cast<std::uint32_t>(n);
  blob.height = 1;
  blob.row_step = blob.point_step * blob.width;
  blob.is_dense = static_cast<std::uint8_t>(sparse.is_dense && dense.is_dense);
  blob.data.resize(n * blob.point_step);
  const std::size_t sparse_bytes = sparse.size() * sizeof(mapping::MapPoint);
  if (!sparse.empty()) std::memcpy(blob.data.data(), sparse.data(), sparse_bytes);
  if (!dense.empty()) {
    std::memcpy(blob.data.data() + sparse_bytes, dense.data(),
                dense.size() * sizeof(mapping::MapPoint));
  }
  mapping::MapCloud().swap(dense);
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
  timings_.push_back(builder_->addKeyframe(kf.t_ns, kf.T_w_b, kf.left, kf.right, kf.landmarks));
}

mapping::PoseLookup mapPoses(const MapRecorder& recorder, const MapPoseSource& source) {
  const auto usable = [](const Trajectory* t) { return t != nullptr && !t->empty(); };
  const Trajectory* fused = usable(source.fused) ? source.fused : nullptr;
  const Trajectory* traj = fused != nullptr ? fused : usable(source.vio) ? source.vio : nullptr;
  const auto lag_ns = static_cast<std::int64_t>(std::llround(source.exposure_lag_s * 1e9));
  if (lag_ns == 0 || traj == nullptr) {
    if (fused == nullptr) return recorder.builder().vioPoses();
    return [fused](std::int64_t t_ns) { return fusion::interpolatePose(*fused, t_ns); };
  }
  // The dense points and landmarks of a keyframe come from its images, taken t_d before the stamp:
  // at 10 m/s a 20 ms lag would otherwise put them 0.2 m along the track.
  return [traj, lag_ns](std::int64_t t_ns) {
    if (auto at_exposure = fusion::interpolatePose(*traj, t_ns - lag_ns)) return at_exposure;
    return fusion::interpolatePose(*traj, t_ns);
  };
}

namespace {

// map.las from the map's blob when the run is georeferenced, else the reason (and no stale file).
nlohmann::json writeLasOrSayWhy(const std::filesystem::path& out, const std::string& frame,
                                const pcl::PCLPointCloud2* blob) {
  const std::filesystem::path file = out / "map.las";
  if (frame != "enu" || blob == nullptr) {
    const std::string reason =
        frame == "enu" ? "the map is empty"
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
  const exporter::LasSummary s = exporter::writeMapLas(file, *blob, georef, out / "map.pcd");
  return {{"written", true},
          {"file", "map.las"},
          {"points", s.points},
          {"crs", fmt::format("EPSG:{} (UTM zone {}{}) + ellipsoidal height", s.crs.epsg(),
                              s.crs.zone, s.crs.north ? "N" : "S")}};
}

// map.pcd, map.ply and map.las from the map's clouds, which are freed; report.json's "las".
nlohmann::json writeCloudFiles(const std::filesystem::path& out, MapRunResult& r) {
  if (r.map.sparse.empty() && r.map.dense.empty()) {
    spdlog::warn("the map is empty (no keyframe had landmarks or depth): no cloud files written");
    return writeLasOrSayWhy(out, r.frame, nullptr);
  }
  const pcl::PCLPointCloud2 blob = mapBlob(r.map.sparse, r.map.dense);
  mapping::MapCloud().swap(r.map.sparse);
  exporter::writePcd(out / "map.pcd", blob);
  exporter::writePly(out / "map.ply", blob);
  return writeLasOrSayWhy(out, r.frame, &blob);
}

}  // namespace

MapRunResult buildAndWriteMap(MapRecorder& recorder, const MapPoseSource& source,
                              bool georeferenced, const std::filesystem::path& out, bool threaded,
                              const std::function<void()>& alongside) {
  MapRunResult r;
  r.frame =
      georeferenced && source.fused != nullptr && !source.fused->empty() ? "enu" : "vio_world";
  const mapping::PoseLookup poses = mapPoses(recorder, source);
  mapping::MapBuildResult occupancy;
  double occupancy_ms = 0.0;
  std::promise<void> clouds_built;
  std::future<void> occupancy_done;
  if (threaded) {
    // The trees grow only once the clouds' filters are done, beside the writing of the cloud
    // files: never both peaks at once. Started with the build, the occupancy was up to 6 s
    // faster on KITTI-00 but held 1760-2180 MiB, depending on thread timing.
    occupancy_done =
        std::async(std::launch::async, [&, clouds = clouds_built.get_future()]() mutable {
          try {
            clouds.get();
          } catch (...) {
            return;  // the clouds failed: the caller reports that
          }
          const auto start = std::chrono::steady_clock::now();
          recorder.buildOccupancy(poses, occupancy);
          occupancy_ms = msSince(start);
        });
  }
  if (alongside) alongside();
  auto start = std::chrono::steady_clock::now();
  r.map = recorder.buildClouds(poses);
  r.build_ms = msSince(start);
  if (threaded) clouds_built.set_value();
  r.las = writeCloudFiles(out, r);

  if (threaded) {
    occupancy_done.get();
    recorder.releaseDense();
    r.map.occupancy = std::move(occupancy.occupancy);
    r.map.occupancy_color = std::move(occupancy.occupancy_color);
    r.map.ms_octomap_per_keyframe = std::move(occupancy.ms_octomap_per_keyframe);
    r.map.counts.occupied_leaves = occupancy.counts.occupied_leaves;
    r.map.counts.octree_bytes = occupancy.counts.octree_bytes;
    r.map.counts.color_octree_bytes = occupancy.counts.color_octree_bytes;
    r.build_ms += occupancy_ms;  // CPU time of both stages, as when run in turn
  } else {
    start = std::chrono::steady_clock::now();
    recorder.buildOccupancyReleasing(poses, r.map);
    r.build_ms += msSince(start);
  }
  writeTreeAtomic(out / "map.bt", *r.map.occupancy, true);
  r.map.occupancy.reset();
  writeTreeAtomic(out / "map.ot", *r.map.occupancy_color, false);
  r.map.occupancy_color.reset();
  return r;
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
