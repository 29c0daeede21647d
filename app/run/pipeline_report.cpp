// gvio run's last stage: the self-evaluation, report.json, config.yaml and the summary lines.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>

#include "io/atomic_write.hpp"
#include "io/run_sources.hpp"
#include "run/pipeline_stages.hpp"
#include "run/report.hpp"
#include "run/stats.hpp"
#include "run/time_offset_summary.hpp"

namespace gvio::run {
namespace {

struct Evaluations {
  std::optional<EvaluationOutcome> loop_closed;  // VIO world, SE(3) aligned
  std::optional<UnalignedOutcome> fused, fused_online;
};

Evaluations evaluate(const RunState& s) {
  Evaluations e;
  const io::Dataset& ds = s.dataset;
  if (!ds.groundtruth || !ds.groundtruth->hasTimestamps()) return e;
  if (!s.georeferenced && s.loops && !s.final_trajectory.empty()) {
    e.loop_closed = evaluateAgainstTruth(*ds.groundtruth, s.final_trajectory);
  }
  // Without alignment the truth must be in the same ENU frame: only with an explicit origin.
  if (s.gnss && !s.gnss->fused.empty() && s.config.fusion.originLla()) {
    e.fused = evaluateUnaligned(*ds.groundtruth, s.gnss->fused);
    if (!s.gnss->fused_online.empty()) {
      e.fused_online = evaluateUnaligned(*ds.groundtruth, s.gnss->fused_online);
    }
  }
  return e;
}

void logSummary(const RunState& s, const Evaluations& e) {
  std::string ape = "no ground truth";
  if (s.evaluation) {
    ape = s.evaluation->result
              ? fmt::format("APE (SE3) rmse {:.3f} m over {:.0f} m",
                            s.evaluation->result->ape_se3.rmse, s.evaluation->result->path_length_m)
              : "not evaluated";
    if (e.loop_closed && e.loop_closed->result) {
      ape += fmt::format(" ({:.3f} m loop-closed)", e.loop_closed->result->ape_se3.rmse);
    }
  }
  if (s.loops) {
    const nlohmann::json& j = s.loops_report;
    if (s.loops->graph.rounds == 0) {
      spdlog::info("loops: {} candidates verified, none accepted: the trajectory is unchanged",
                   j["verified"].get<int>());
    } else {
      spdlog::info(
          "loops: {} candidates verified, {} accepted, {} kept by the global graph ({} rounds, {}, "
          "{:.0f} ms)",
          j["verified"].get<int>(), j["accepted"].get<int>(), j["graph"]["active_loops"].get<int>(),
          j["graph"]["rounds"].get<int>(), s.loops->graph.converged ? "converged" : "NOT converged",
          s.loops->graph.ms_solve);
    }
    if (s.loops->graph.rounds > 0 && !s.loops->graph.converged) {
      spdlog::warn("the global pose graph did not converge: {}", s.loops->graph.termination);
    }
  }
  if (s.gnss) {
    std::string fused_ape;
    if (e.fused && e.fused->ape) {
      fused_ape = fmt::format(", fused APE (no alignment) rmse {:.3f} m", e.fused->ape->rmse);
      if (e.fused_online && e.fused_online->ape) {
        fused_ape += fmt::format(" final, {:.3f} m online", e.fused_online->ape->rmse);
      }
    }
    const fusion::FusionStats& g = s.gnss->stats;
    std::string smoother;
    if (s.gnss->smoothed) {
      smoother = fmt::format(", smoother: {} left out, sigmas x", g.smoother_outliers);
      for (const auto& [quality, scale] : g.smoother_sigma_scale) {
        smoother += fmt::format(" {:.2f} h / {:.2f} v (quality {})", scale.x(), scale.y(), quality);
      }
    }
    spdlog::info("GNSS {}: {} fixes used, {} rejected, {} skipped, {} outage(s){}{}",
                 fusion::toString(s.gnss->mode), g.fixes_used, g.fixes_rejected,
                 s.gnss->screening.skipped(), g.outages.size(), smoother, fused_ape);
  }
  const TimingSummary total = summarizeTimings(s.vio.timings.total_ms);
  std::string time_offset = timeOffsetText(vioTimeOffset(s.vio));
  if (!time_offset.empty()) time_offset = ", " + time_offset;
  spdlog::info(
      "{} frames, {} keyframes, {} poses written, {}, {:.1f} ms/frame (p95 {:.1f}){}{}; wrote {}",
      s.vio.counters.frames, s.vio.counters.keyframes, s.vio.trajectory.size(), ape, total.mean,
      total.p95, time_offset, partialNote(vioCoverage(s.dataset, s.vio)), s.request.out.string());
}

}  // namespace

void writeReport(RunState& s) {
  const Evaluations e = evaluate(s);
  ReportContext context;
  context.map = s.map_report;
  context.loops = s.loops_report;
  context.command_line = s.request.command_line;
  context.gnss_requested = s.request.gnss;
  context.gnss_noise = s.gnss_noise;
  context.imu_noise_source = s.imu_noise_source;
  if (!s.imu_noise_source.empty()) context.imu_noise = s.estimator.imu_noise;
  context.peak_rss_mb = peakRssMb();
  context.evaluation = s.evaluation ? &*s.evaluation : nullptr;
  context.evaluation_loop_closed = e.loop_closed ? &*e.loop_closed : nullptr;
  context.gnss = s.gnss ? &*s.gnss : nullptr;
  context.evaluation_fused = e.fused ? &*e.fused : nullptr;
  context.evaluation_fused_online = e.fused_online ? &*e.fused_online : nullptr;
  nlohmann::json report = buildReport(s.dataset, s.vio, context);
  // The report's own writing is the last stage: its time is in run_wall_s, not in stage_wall_s.
  report["run_wall_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - s.started).count();
  report["stage_wall_s"] = s.stage_wall_s;
  // The VIO noise model the fusion's graphs and the loop search used (config.yaml says auto
  // where the VIO mode chose it).
  report["vio_noise"] = {{"drift_fraction", s.fusion.vio_drift_fraction},
                         {"sigma_floor_m", s.fusion.vio_sigma_floor_m},
                         {"rot_drift_rad_per_m", s.fusion.vio_rot_drift_rad_per_m},
                         {"rot_floor_rad", s.fusion.vio_rot_floor_rad}};
  report["sources"] = io::sourcesJson(
      {s.request.dataset, s.request.format, s.request.calib_files, s.request.gnss_file},
      s.dataset.format);
  io::writeTextAtomic(s.request.out / "report.json", report.dump(2) + "\n");
  io::writeTextAtomic(s.request.out / "config.yaml", s.request.config_yaml);
  logSummary(s, e);
}

}  // namespace gvio::run
