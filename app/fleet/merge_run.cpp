#include "fleet/merge_run.hpp"

#include <malloc.h>
#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <set>

#include "fleet/merge_align.hpp"
#include "fusion/enu_utm_grid.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "run/stats.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// A run's map.pcd into the spill, in the merge's UTM zone, carried onto the joint alignment's
// poses when it moved.
std::uint64_t spillRun(const MergeRun& run, const MergeFrame& frame, TileSpill& spill,
                       mapping::MapCorrection* correction) {
  const io::MapCloud cloud = io::readMapCloud(run.dir / "map.pcd");
  fusion::EnuToUtmGrid grid(run.georef.enu_origin, frame.crs.zone, frame.crs.north);
  std::uint64_t added = 0;
  for (std::size_t k = 0; k < cloud.p_enu.size(); ++k) {
    Eigen::Vector3d p_enu = cloud.p_enu[k].cast<double>();
    if (!p_enu.allFinite()) continue;
    if (correction != nullptr) p_enu = correction->apply(p_enu);
    const float intensity = cloud.intensity.empty() ? 0.0F : cloud.intensity[k];
    const auto las_intensity =
        static_cast<std::uint16_t>(std::clamp(intensity, 0.0F, 255.0F) * 257.0F);
    const std::uint8_t source = cloud.source.empty() ? io::MapCloud::kSparse : cloud.source[k];
    spill.add(grid.toUtm(p_enu), las_intensity, run.point_source_id, source);
    ++added;
  }
  return added;
}

// A run's track from its trajectory_lla.csv, carried onto the joint alignment's poses as its
// points are (through the run's own ENU frame), so that the tracks lie on the merged map.
std::vector<fusion::Lla> runTrack(const MergeRun& run, mapping::MapCorrection* correction) {
  const fs::path csv = run.dir / "trajectory_lla.csv";
  if (!fs::exists(csv)) {
    spdlog::warn("merge: {} has no trajectory_lla.csv: no track in tiles.geojson", run.name);
    return {};
  }
  std::vector<fusion::Lla> track = readTrack(csv);
  if (correction == nullptr) return track;
  const fusion::EnuFrame enu(run.georef.enu_origin);
  for (fusion::Lla& lla : track) lla = enu.toLla(correction->apply(enu.toEnu(lla)));
  return track;
}

void logAlignment(const std::vector<MergeRun>& runs, const MergeAlignment& a) {
  if (!a.attempted) return;
  spdlog::info(
      "merge: alignment: {} pair(s) of keyframes of different drives within reach, {} verified, "
      "{} accepted, {} kept by the joint graph{}",
      a.pairs_in_radius, a.verified, a.accepted, a.active,
      a.solved ? fmt::format(" ({} rounds, {:.0f} ms, {})", a.graph.rounds, a.graph.ms_solve,
                             a.graph.converged ? "converged" : "NOT converged")
               : "");
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const DriveMovement& m = a.drives[r];
    if (!m.aligned) {
      spdlog::info("merge: alignment: {}: not moved ({})", runs[r].name, m.note);
      continue;
    }
    spdlog::info(
        "merge: alignment: {}: {} loop(s) to other drives; moved {:.3f} m on average, "
        "{:.3f} m at most, turned {:.3f} deg at most",
        runs[r].name, m.loops_active, m.moved_mean_m, m.moved_max_m, m.rotated_max_deg);
  }
}

// Tiles of an earlier merge into this folder that this one did not write.
void removeStaleTiles(const fs::path& tiles_dir, const std::set<std::string>& written) {
  for (const auto& entry : fs::directory_iterator(tiles_dir)) {
    const fs::path p = entry.path();
    const std::string ext = p.extension().string();
    const bool tile_file = ext == ".las" || ext == ".pcd" || ext == ".bt";
    if (tile_file && p.stem().string().starts_with("E") && !written.count(p.stem().string())) {
      fs::remove(p);
    }
  }
}

// A merge streams each run's cloud and each tile through buffers of tens to hundreds of MB that
// live for one run or one tile. glibc serves those from fresh mmaps and unmaps them when freed,
// so every one is faulted in again page by page: that took half of a merge's time on a virtual
// machine (measured: 10 KITTI-00 runs merged in 60.5 s, 32.1 s with the heap kept). Kept in the
// heap instead, a freed buffer is reused by the next run or tile; the peak stays the same, as the
// buffers of a run or a tile are never alive together with the next one's.
void keepLargeBuffersInTheHeap() {
  constexpr int kThresholdBytes = 1 << 30;
  mallopt(M_MMAP_THRESHOLD, kThresholdBytes);
  mallopt(M_TRIM_THRESHOLD, kThresholdBytes);
}

}  // namespace

MergeSummary runMerge(const MergeRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  keepLargeBuffersInTheHeap();
  request.config.validate();
  const std::vector<MergeRun> runs = resolveMergeRuns(request.runs);
  const MergeFrame frame = chooseMergeFrame(runs, request.config);
  const fs::path tiles_dir = request.out_dir / "tiles";
  std::error_code ec;
  fs::create_directories(tiles_dir, ec);
  if (ec) throw io::InputError(request.out_dir, 0, "cannot create the folder: " + ec.message());

  MergeAlignment alignment;
  if (request.config.align) {
    try {
      alignment = alignDrives(runs, request.loops, request.fusion);
    } catch (const InvalidInput&) {
      throw;  // a damaged keyframes.bin or a bad loops.* value: the user's to mend
    } catch (const std::exception& e) {
      // A bug or an odd drive inside the alignment costs the alignment, never the merge.
      spdlog::warn("merge: the joint alignment failed ({}): the drives are merged as they are",
                   e.what());
      alignment = MergeAlignment{};
      alignment.drives.resize(runs.size());
      alignment.error = e.what();
      alignment.csv = alignmentLoopsHeader();
    }
    io::writeTextAtomic(request.out_dir / "alignment.json",
                        alignmentJson(runs, alignment).dump(2) + "\n");
    io::writeTextAtomic(request.out_dir / "alignment_loops.csv", alignment.csv);
    logAlignment(runs, alignment);
  }
  MergeSummary summary;
  summary.tile_size_m = request.config.tile_size_m;
  TileSpill spill(request.out_dir / fmt::format(".merge-scratch-{}", ::getpid()),
                  request.config.tile_size_m, frame.origin_utm.z());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const MergeRun& run = runs[r];
    mapping::MapCorrection* correction = nullptr;
    if (r < alignment.corrections.size() && alignment.corrections[r]) {
      correction = &*alignment.corrections[r];
    }
    const std::uint64_t n = spillRun(run, frame, spill, correction);
    summary.tracks[run.point_source_id] = runTrack(run, correction);
    if (correction != nullptr) alignment.corrections[r].reset();  // its cell cache is done
    summary.points_per_drive[run.point_source_id] = n;
    summary.points += n;
    spdlog::info("merge: {} ({} points, point source ID {})", run.name, n, run.point_source_id);
  }
  spill.flushAll();
  const auto spilled = std::chrono::steady_clock::now();
  spdlog::debug("merge: first pass (read, convert, spill) {:.2f} s",
                std::chrono::duration<double>(spilled - start).count());
  std::set<std::string> written;
  for (const auto& [key, count] : spill.counts()) {
    summary.tiles.push_back(
        writeTile(request.out_dir, frame, spill, key, request.config, summary.agreement));
    written.insert(summary.tiles.back().name);
  }
  removeStaleTiles(tiles_dir, written);
  spdlog::debug("merge: second pass (tiles) {:.2f} s",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - spilled).count());
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.points_per_s =
      summary.wall_s > 0.0 ? static_cast<double>(summary.points) / summary.wall_s : 0.0;
  summary.peak_rss_mb = run::peakRssMb();
  writeMergeIndex(request.out_dir, runs, frame, summary);
  spdlog::info(
      "merge: {} points of {} run(s) in {} tile(s) of {} m, UTM zone {}{} (EPSG:{}); "
      "{:.1f} s, {:.2f} M points/s; {}",
      summary.points, runs.size(), summary.tiles.size(), summary.tile_size_m, frame.crs.zone,
      frame.crs.north ? "N" : "S", frame.crs.epsg(), summary.wall_s, summary.points_per_s / 1e6,
      (request.out_dir / "tiles.json").string());
  for (const MergeRun& run : runs) {
    const auto it = summary.agreement.find(run.point_source_id);
    if (it == summary.agreement.end() || it->second.overlap == 0) continue;
    const DriveAgreement& a = it->second;
    spdlog::info(
        "merge: {}: {:.1f} % of {} overlapping dense points (a sample) within {} m of an "
        "earlier drive's (median {:.3f} m)",
        run.name, 100.0 * static_cast<double>(a.within) / static_cast<double>(a.overlap), a.overlap,
        DriveAgreement::kWithinM, a.medianM());
  }
  return summary;
}

}  // namespace gvio::fleet
