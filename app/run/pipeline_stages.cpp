// gvio run's middle stages: VIO, GNSS fusion, loop closure, trajectories, map.
#include "run/pipeline_stages.hpp"

#include <spdlog/spdlog.h>

#include "io/atomic_write.hpp"
#include "io/loops_csv.hpp"
#include "io/place_database_io.hpp"
#include "io/trajectory_io.hpp"
#include "run/run_status.hpp"
#include "run/time_offset_summary.hpp"

namespace gvio::run {
namespace {

// The estimator bridges an IMU gap longer than max_imu_gap_s on vision alone (vio_prediction.cpp):
// worth a warning, since a recording with such gaps is usually a dropped or mis-stamped log.
void warnImuGaps(const io::Dataset& ds, const odometry::EstimatorConfig& estimator) {
  if (!odometry::usesImu(estimator.mode) || ds.imu.size() < 2) return;
  const auto max_gap_ns = static_cast<std::int64_t>(estimator.max_imu_gap_s * 1e9);
  std::size_t gaps = 0, longest = 1;
  for (std::size_t i = 1; i < ds.imu.size(); ++i) {
    const std::int64_t dt = ds.imu[i].t_ns - ds.imu[i - 1].t_ns;
    if (dt <= max_gap_ns) continue;
    ++gaps;
    if (dt > ds.imu[longest].t_ns - ds.imu[longest - 1].t_ns) longest = i;
  }
  if (gaps == 0) return;
  const std::int64_t t0 = ds.frames.empty() ? ds.imu.front().t_ns : ds.frames.front().t_ns;
  spdlog::warn(
      "{}: {} gap(s) in the IMU longer than vio.max_imu_gap_s = {:.2f} s, the longest {:.2f} s "
      "from t = {:.2f} s: the VIO bridges them on vision alone",
      ds.root.string(), gaps, estimator.max_imu_gap_s,
      static_cast<double>(ds.imu[longest].t_ns - ds.imu[longest - 1].t_ns) * 1e-9,
      static_cast<double>(ds.imu[longest - 1].t_ns - t0) * 1e-9);
}

}  // namespace

void runVioStage(RunState& s) {
  const io::Dataset& ds = s.dataset;
  s.estimator = s.config.vio.estimator;
  s.estimator.mode = chooseVioMode(s.config.vio.mode, ds);
  s.fusion = s.config.fusion.fusionFor(s.estimator.mode);
  s.fusion.lever_arm_b = gnssLeverArm(s.fusion.lever_arm_b, ds);
  const ImuConfig::Choice imu_noise = s.config.imu.choose(ds.imu_noise);
  s.estimator.imu_noise = imu_noise.noise;
  s.estimator.validate();
  warnImuGaps(ds, s.estimator);
  if (odometry::usesImu(s.estimator.mode)) s.imu_noise_source = imu_noise.source;
  const std::filesystem::path& out = s.request.out;
  spdlog::info("{} {} ({}): {} frames, mode {}", io::toString(ds.format), ds.root.string(),
               ds.variant, ds.frames.size(), odometry::toString(s.estimator.mode));
  if (s.config.map.enabled) s.map_recorder.emplace(s.config.map.map);
  if (s.config.loops.detection.enabled) {
    s.loop_recorder.emplace(s.config.loops.detection.features);
  }
  VioRunOptions options;
  options.progress = s.request.progress;
  options.threads = s.request.threads;
  if (s.request.pending_signal) {
    options.stop = [&s] { return s.request.pending_signal() != 0; };
  }
  if (s.map_recorder || s.loop_recorder) {
    // Only the keyframe thread touches the recorders until runVio returns.
    options.on_keyframe = [&s](const KeyframeInput& kf) {
      if (s.map_recorder) s.map_recorder->addKeyframe(kf);
      if (s.loop_recorder) s.loop_recorder->addKeyframe(kf);
    };
  }
  s.vio = runVio(ds, s.estimator, options);
  if (s.request.progress_done) s.request.progress_done();
  if (s.vio.stopped) stopIfInterrupted(s);  // nothing of a cut-short VIO is written
  if (s.vio.trajectory.empty()) {
    spdlog::warn("the estimator never initialised: trajectory_vio.tum is empty");
    io::writeTextAtomic(out / "trajectory_vio.tum", "");
  } else {
    io::writeTum(out / "trajectory_vio.tum", s.vio.trajectory);
  }
  if (ds.groundtruth && ds.groundtruth->hasTimestamps()) {
    io::writeTum(out / "groundtruth.tum", *ds.groundtruth);  // for gvio render's error view
    s.evaluation = evaluateAgainstTruth(*ds.groundtruth, s.vio.trajectory);
    if (!s.evaluation->result) spdlog::warn("no evaluation: {}", s.evaluation->error);
  }
}

void runGnssStage(RunState& s) {
  // auto fuses with the graph when the dataset has fixes; without fixes every mode is pure VIO.
  const std::string& gnss = s.request.gnss;
  const bool fuse = gnss != "off" && !s.dataset.gnss.empty();
  if (!fuse && (gnss == "kf" || gnss == "graph")) {
    spdlog::warn("--gnss {}: the dataset has no GNSS fixes: pure VIO", gnss);
  }
  if (!fuse) return;
  const fusion::FusionMode mode =
      gnss == "kf" ? fusion::FusionMode::kKf : fusion::FusionMode::kGraph;
  s.gnss = fuseGnss(s.dataset, s.vio.trajectory, mode, s.fusion, s.config.fusion.originLla(),
                    odometry::usesImu(s.estimator.mode));
  if (s.gnss && !s.gnss->fused.empty()) {
    s.final_trajectory = s.gnss->fused;
    s.georeferenced = true;
  }
}

void runLoopStage(RunState& s) {
  if (!s.loop_recorder || s.loop_recorder->empty()) return;
  try {
    s.loops = closeLoops(*s.loop_recorder, s.vio.trajectory, s.gnss ? &*s.gnss : nullptr,
                         odometry::usesImu(s.estimator.mode), s.config.loops, s.fusion);
  } catch (const std::exception& e) {
    // A bug or an odd drive inside loop closure must not cost the user the run.
    spdlog::warn("loop closure failed ({}): the run goes on without it", e.what());
    s.loops_report = {{"error", e.what()}};
  }
  if (s.config.loops.save_keyframes && s.loops && s.gnss) {
    const Trajectory& final_enu = s.loops->trajectory.empty() ? s.gnss->fused : s.loops->trajectory;
    const auto db = placeDatabase(*s.loop_recorder, s.vio.trajectory, final_enu, *s.gnss, &*s.loops,
                                  odometry::usesImu(s.estimator.mode), s.config.loops, s.fusion);
    if (db) io::writePlaceDatabase(s.request.out / "keyframes.bin", *db);
  }
  s.loop_recorder.reset();  // the features are no longer needed: free them before the map
  if (!s.loops) return;
  io::writeLoopsCsv(s.request.out / "loops.csv", s.loops->rows);
  s.loops_report = loopsReport(*s.loops);
  if (s.loops->trajectory.empty()) return;
  s.final_trajectory = s.loops->trajectory;
  s.georeferenced = s.loops->frame == "enu";
  if (s.georeferenced && s.gnss) {
    // trajectory.tum is now the loop-closed one; the smoother's covariances describe the poses
    // before the loops, so they are not written with it. In kf mode the filter's causal output
    // stays available as trajectory_online.tum (graph mode already keeps its causal one there).
    if (s.gnss->fused_online.empty()) s.gnss->fused_online = s.gnss->fused;
    s.gnss->fused = s.loops->trajectory;
    s.gnss->fused_covariance.clear();
  }
}

void writeTrajectories(RunState& s) {
  if (s.gnss) {
    writeGeoreferencedOutputs(s.request.out, *s.gnss);  // trajectory.tum in ENU, georef.json
  }
  if (!s.georeferenced && !s.final_trajectory.empty()) {
    io::writeTum(s.request.out / "trajectory.tum", s.final_trajectory);  // loop-closed VIO world
  }
}

void runMapStage(RunState& s) {
  if (!s.map_recorder || s.map_recorder->empty()) {
    if (s.request.two_pass) {
      spdlog::warn("--two-pass: the run has no map (map.enabled false, or no keyframe)");
    }
    return;
  }
  const MapPoseSource poses{s.final_trajectory.empty() ? nullptr : &s.final_trajectory,
                            &s.vio.trajectory,
                            s.vio.time_offset_estimated ? vioTimeOffset(s.vio).t_d_s : 0.0};
  // Before the build frees the keyframes' dense points (beside the occupancy when threaded).
  nlohmann::json two_pass_report, revisits;
  const auto looks = [&] {
    if (s.request.two_pass) {
      two_pass_report = twoPassReport(*s.map_recorder, mapPoses(*s.map_recorder, poses),
                                      *s.request.two_pass, s.dataset.frames.front().t_ns);
    }
    revisits = revisitReport(*s.map_recorder, mapPoses(*s.map_recorder, poses));
  };
  const MapRunResult map = buildAndWriteMap(*s.map_recorder, poses, s.georeferenced, s.request.out,
                                            s.request.threads >= 2, looks);
  s.map_report = mapReport(*s.map_recorder, map);
  if (s.request.two_pass) s.map_report["two_pass"] = two_pass_report;
  s.map_report["revisits"] = revisits;
  s.map_report["las"] = map.las;
  s.map_recorder.reset();
  spdlog::info("map ({}): {} landmarks, {} dense points, {} occupied voxels", map.frame,
               map.map.counts.sparse_points, map.map.counts.dense_points,
               map.map.counts.occupied_leaves);
}

}  // namespace gvio::run
