#include "run/report.hpp"

#include "run/time_offset_summary.hpp"

#include <algorithm>

#include "io/dataset_summary.hpp"
#include "run/coverage.hpp"
#include "run/stats.hpp"
#include "run/time_offset_summary.hpp"

namespace gvio::run {
namespace {

using nlohmann::json;

json timingJson(const std::vector<double>& samples_ms) {
  const TimingSummary s = summarizeTimings(samples_ms);
  return {{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}};
}

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) * 1e-9;
}

json statsJson(const eval::Stats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"min", s.min},
          {"max", s.max},   {"n", s.n}};
}

json evaluationJson(const EvaluationOutcome& outcome) {
  if (!outcome.result) return {{"error", outcome.error}};
  const RunEvaluation& e = *outcome.result;
  return {{"ape_se3", statsJson(e.ape_se3)},
          {"rpe_100m_percent", e.rpe_100m_percent ? json(*e.rpe_100m_percent) : json(nullptr)},
          {"path_length_m", e.path_length_m}};
}

// t_d: how much image stamps lag the exposures, after the calibration's timeshift; the total lag
// of the raw stamps is t_d - timeshift_cam_imu (Kalibr: t_imu = t_cam + timeshift).
json timeOffsetJson(const io::Dataset& ds, const VioRunResult& run) {
  json history = json::array();
  for (const auto& [t_ns, t_d] : run.time_offset_history) history.push_back({seconds(t_ns), t_d});
  const TimeOffsetSummary summary = vioTimeOffset(run);
  json j = {{"estimated", run.time_offset_estimated},
            {"calibration_timeshift_cam_imu_s", ds.camera_timeshift_s},
            {"stamp_lag_s", summary.t_d_s - ds.camera_timeshift_s},
            {"held_solves", run.counters.time_offset_held_solves},
            {"history", history}};
  j.update(timeOffsetSummaryJson(summary));
  return j;
}

}  // namespace

json datasetJson(const io::Dataset& ds) {
  json j = {{"path", ds.root.string()},
            {"format", io::toString(ds.format)},
            {"variant", ds.variant},
            {"cameras", ds.cameras.size()},
            {"frames", ds.frames.size()},
            {"imu_samples", ds.imu.size()},
            {"imu_rate_hz", imuRateHz(ds)},
            {"gnss_fixes", ds.gnss.size()},
            {"groundtruth", ds.groundtruth ? json(ds.groundtruth_source) : json(nullptr)}};
  if (!ds.bag_topics.empty()) j["bag_topics"] = io::bagTopicsJson(ds);
  // What the readers warned of (also on stderr), so a report read later still says it.
  j["warnings"] = ds.warnings;
  return j;
}

Coverage vioCoverage(const io::Dataset& ds, const VioRunResult& run) {
  std::vector<std::int64_t> frames;
  frames.reserve(ds.frames.size());
  for (const auto& f : ds.frames) frames.push_back(f.t_ns);
  return coverageOf(frames, run.trajectory.t_ns);
}

json buildReport(const io::Dataset& ds, const VioRunResult& run, const ReportContext& ctx) {
  json report;
  report["gvio_version"] = GVIO_VERSION;
  // A run in progress or cut short says so (run/run_status.hpp); one that started late, "partial".
  const Coverage coverage = vioCoverage(ds, run);
  report["status"] = runStatus(coverage);
  report["coverage"] = coverageJson(coverage);
  report["command_line"] = ctx.command_line;
  report["dataset"] = datasetJson(ds);
  report["mode"] = odometry::toString(run.mode);
  report["imu_noise_source"] =
      ctx.imu_noise_source.empty() ? json(nullptr) : json(ctx.imu_noise_source);
  report["imu_noise"] = ctx.imu_noise ? io::imuNoiseJson(*ctx.imu_noise) : json(nullptr);
  // The lens model the rectifier undistorted (a stereo pair shares one); "none" for pinholes.
  std::string distortion = "none";
  const std::size_t used = odometry::usesStereo(run.mode) ? 2 : 1;
  for (std::size_t i = 0; i < std::min(used, ds.cameras.size()); ++i) {
    const CameraModel& cam = ds.cameras[i];
    if (!hasLensDistortion(cam)) continue;
    distortion =
        cam.distortion.size() == 8 ? "rational_polynomial" : toString(cam.distortion_model);
  }
  report["rectification"] = {{"identity", run.rectification_identity},
                             {"baseline_m", run.baseline_m},
                             {"distortion_model", distortion}};
  const odometry::VioCounters& c = run.counters;
  report["counts"] = {{"frames", c.frames},
                      {"keyframes", c.keyframes},
                      {"initializations", c.initializations},
                      {"lost_frames", c.lost_frames},
                      {"coasted_frames", c.coasted_frames},
                      {"imu_gaps", c.imu_gaps},
                      {"exposure_corrected_frames", c.exposure_corrected_frames},
                      {"stereo_gain_corrected_frames", c.stereo_gain_corrected_frames},
                      {"frames_skipped_unreadable", run.frames_skipped_unreadable},
                      {"poses_written", run.trajectory.size()},
                      {"poses_nonfinite", run.nonfinite_poses}};
  const auto per_frame = [&](std::int64_t sum) {
    return c.frames > 0 ? static_cast<double>(sum) / c.frames : 0.0;
  };
  report["tracker"] = {
      {"tracked_per_frame", per_frame(c.tracked_features)},
      {"new_per_frame", per_frame(c.new_features)},
      {"rejected_forward_backward_per_frame", per_frame(c.rejected_forward_backward)},
      {"rejected_ransac_per_frame", per_frame(c.rejected_ransac)},
      {"stereo_matches_per_frame", per_frame(c.stereo_matches)},
      {"rejected_stereo_per_frame", per_frame(c.rejected_stereo)}};
  report["timing_ms"] = {{"image_load", timingJson(run.timings.load_ms)},
                         {"rectify", timingJson(run.timings.rectify_ms)},
                         {"tracking", timingJson(run.timings.tracking_ms)},
                         {"estimator", timingJson(run.timings.estimator_ms)},
                         {"total", timingJson(run.timings.total_ms)}};
  report["time_offset"] = timeOffsetJson(ds, run);
  report["wall_s"] = run.wall_s;
  report["peak_rss_mb"] = ctx.peak_rss_mb;
  if (!ctx.map.is_null()) report["map"] = ctx.map;
  if (!ctx.loops.is_null()) report["loops"] = ctx.loops;
  if (ctx.gnss) {
    report["gnss"] = gnssReport(*ctx.gnss, ds.gnss.size());
    report["gnss"]["requested"] = ctx.gnss_requested;
    if (!ctx.gnss_noise.is_null()) report["gnss"]["noise_added"] = ctx.gnss_noise;
    report["outages"] = outagesReport(*ctx.gnss);
  } else {
    report["gnss"] = {{"requested", ctx.gnss_requested},
                      {"mode", "off"},
                      {"fixes", run.gnss_fixes},
                      {"used", 0},
                      {"rejected", 0}};
    report["outages"] = json::array();
  }
  json events = json::array();
  for (const odometry::VioEvent& e : run.events) {
    events.push_back({{"t", seconds(e.t_ns)}, {"kind", e.kind}, {"message", e.message}});
  }
  report["events"] = std::move(events);
  if (ctx.evaluation) report["evaluation"] = evaluationJson(*ctx.evaluation);
  if (ctx.evaluation_loop_closed) {
    report["evaluation_loop_closed"] = evaluationJson(*ctx.evaluation_loop_closed);
    report["evaluation_loop_closed"]["trajectory"] =
        "trajectory.tum: the loop-closed trajectory in the VIO world, SE(3) aligned";
  }
  if (ctx.evaluation_fused) {
    const UnalignedOutcome& e = *ctx.evaluation_fused;
    report["evaluation_fused"] =
        e.ape ? json{{"ape_none", statsJson(*e.ape)},
                     {"note",
                      "no alignment, in the ENU frame of fusion.origin (the truth's must "
                      "match)"}}
              : json{{"error", e.error}};
    const UnalignedOutcome* online = ctx.evaluation_fused_online;
    if (e.ape && online && online->ape) {
      report["evaluation_fused"]["ape_none_online"] = statsJson(*online->ape);
      report["evaluation_fused"]["trajectory"] =
          "ape_none: trajectory.tum (the final trajectory: loop-closed when loops.applied, else "
          "smoothed over all fixes in graph mode); ape_none_online: trajectory_online.tum "
          "(causal)";
    }
  }
  return report;
}

}  // namespace gvio::run
