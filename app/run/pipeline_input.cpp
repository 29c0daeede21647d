// gvio run's first stages: the dataset, its GNSS degraded on request, and the GNSS/INS run for
// datasets without a camera.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>

#include "io/atomic_write.hpp"
#include "io/dataset_sources.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"
#include "run/ins_run.hpp"
#include "run/pipeline_stages.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {
namespace fs = std::filesystem;

// --gnss-noise: the dataset's (accurate) fixes degraded with a receiver error model, so a real
// RTK-grade drive reproduces the reference experiment's SPP-grade GNSS. Returns report.json's
// record of it (null for none).
nlohmann::json degradeGnss(io::Dataset& ds, const RunRequest& request) {
  if (!request.gnss_noise) return nullptr;
  const sim::GnssErrorModel& model = *request.gnss_noise;
  const std::string& spec = request.gnss_noise_name;
  if (ds.gnss.empty()) {
    spdlog::warn("--gnss-noise {}: the dataset has no GNSS fixes to degrade", spec);
    return nullptr;
  }
  const sim::DegradedFixes degraded = sim::degradeFixes(ds.gnss, model, request.seed);
  ds.gnss = degraded.fixes;
  double sum_sq = 0.0;
  for (const Eigen::Vector3d& e : degraded.added_error_enu) sum_sq += e.squaredNorm();
  const double rms_m = std::sqrt(sum_sq / static_cast<double>(degraded.fixes.size()));
  spdlog::info(
      "--gnss-noise {} (seed {}): {} fixes degraded, added error rms {:.2f} m, {} outliers", spec,
      request.seed, degraded.fixes.size(), rms_m, degraded.outliers);
  return {{"model", spec},
          {"seed", request.seed},
          {"white_h_m", model.white_h_m},
          {"white_v_m", model.white_v_m},
          {"bias_m", model.bias_m},
          {"bias_tau_s", model.bias_tau_s},
          {"outlier_probability", model.outlier_probability},
          {"outliers", degraded.outliers},
          {"added_error_rms_m", rms_m}};
}

}  // namespace

void makeOutputDir(const fs::path& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out)) {
    throw InvalidInput(out.string() + ": cannot create the output folder" +
                       (ec ? " (" + ec.message() + ")" : std::string()));
  }
}

void loadDataset(RunState& s) {
  s.dataset = io::openDataset(
      {s.request.dataset, s.request.format, s.request.calib_files, s.request.gnss_file},
      s.config.dataset);
  for (const auto& w : s.dataset.warnings) spdlog::warn("{}", w);
  s.gnss_noise = degradeGnss(s.dataset, s.request);
}

Eigen::Vector3d gnssLeverArm(const Eigen::Vector3d& configured, const io::Dataset& ds) {
  return configured.isZero() && ds.gnss_lever_arm_b ? *ds.gnss_lever_arm_b : configured;
}

// No camera frames but an IMU and GNSS: GNSS/INS on the IMU (run/ins_run.hpp) instead of VIO.
bool runGnssInsInstead(RunState& s) {
  const io::Dataset& ds = s.dataset;
  if (!wantsGnssIns(ds) || s.request.gnss == "off") return false;
  const ImuConfig::Choice imu_noise = s.config.imu.choose(ds.imu_noise);
  fusion::InsConfig ins = s.config.fusion.insConfig(imu_noise.noise);
  ins.lever_arm_b = gnssLeverArm(ins.lever_arm_b, ds);
  const fs::path& out = s.request.out;
  spdlog::info("{} {} ({}): no camera frames, {} IMU samples, {} fixes: GNSS/INS",
               io::toString(ds.format), ds.root.string(), ds.variant, ds.imu.size(),
               ds.gnss.size());
  const InsRunResult r = runGnssIns(ds, ins, s.config.fusion.originLla());
  writeGnssInsOutputs(out, r);
  std::optional<InsEvaluation> evaluation;
  if (ds.groundtruth && ds.groundtruth->hasTimestamps() && ds.groundtruth_enu_origin) {
    const Trajectory truth = reexpressEnu(*ds.groundtruth, *ds.groundtruth_enu_origin, r.origin);
    io::writeTum(out / "groundtruth.tum", truth);  // for gvio render's error view
    evaluation = evaluateGnssIns(r, truth);
  }
  InsReportContext context;
  context.command_line = s.request.command_line;
  context.gnss_requested = s.request.gnss;
  context.gnss_noise = s.gnss_noise;
  context.imu_noise_source = imu_noise.source;
  context.imu_noise = imu_noise.noise;
  context.peak_rss_mb = peakRssMb();
  context.evaluation = evaluation ? &*evaluation : nullptr;
  io::writeTextAtomic(out / "report.json", gnssInsReport(ds, r, context).dump(2) + "\n");
  io::writeTextAtomic(out / "config.yaml", s.request.config_yaml);
  std::string figures;
  if (evaluation && evaluation->fused_h && evaluation->raw_h) {
    figures = fmt::format(
        "; position rmse vs truth: fused {:.3f} m horizontal / {:.3f} m 3-D, raw fixes {:.3f} / "
        "{:.3f} m",
        evaluation->fused_h->rmse, evaluation->fused_3d->rmse, evaluation->raw_h->rmse,
        evaluation->raw_3d->rmse);
  }
  const Coverage coverage = insCoverage(ds, r);
  std::string init = "; not initialised";
  if (r.stats.t_init_ns) {
    init = fmt::format("; heading from the {} ({:.1f} deg)",
                       r.stats.init_method == "track" ? "track alignment" : "GNSS course",
                       r.stats.init_heading_sigma_deg);
  }
  if (r.stats.mount) {
    const Eigen::Vector3d rpy = r.stats.mount->rpy_rad * 180.0 / M_PI;
    init +=
        fmt::format(", mount estimated rpy {:.1f} {:.1f} {:.1f} deg", rpy.x(), rpy.y(), rpy.z());
  }
  spdlog::info(
      "GNSS/INS: {} fixes used, {} rejected, {} before init, {} outage(s), time offset {:.3f} +- "
      "{:.3f} s{}{}{}; wrote {}",
      r.stats.fixes_used, r.stats.fixes_rejected, r.stats.fixes_before_init, r.stats.outages.size(),
      r.final_state.time_offset_s, r.time_offset_sigma_s, init, figures, partialNote(coverage),
      out.string());
  return true;
}

}  // namespace gvio::run
