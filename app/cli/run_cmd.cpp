// gvio run: visual-inertial odometry over a recorded (or simulated) drive, written as a run folder
// (trajectory_vio.tum, report.json, config.yaml; DESIGN.md section 4). The pipeline lives in
// app/run; this file only turns the command line into a run and its outputs into files.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>

#include "cli/app.hpp"
#include "io/atomic_write.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"
#include "run/evaluation.hpp"
#include "run/gnss_run.hpp"
#include "run/ins_run.hpp"
#include "run/map_passes.hpp"
#include "run/map_run.hpp"
#include "run/report.hpp"
#include "run/stats.hpp"
#include "run/vio_runner.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

struct RunOptions {
  std::string dataset;
  std::string format = "auto";
  std::string gnss = "auto";
  std::string gnss_noise = "none";
  std::uint64_t seed = 1;
  std::string out = "out/run";
  std::optional<std::string> two_pass;
  ConfigOptions config;
};

// Checked here rather than by CLI11 so that a bad value is the usual one-line error (exit 2).
void checkGnssOption(const std::string& gnss) {
  if (gnss != "auto" && gnss != "off" && gnss != "kf" && gnss != "graph") {
    throw InvalidInput("--gnss '" + gnss + "': expected auto, off, kf or graph");
  }
}

void makeOutputDir(const fs::path& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out)) {
    throw InvalidInput(out.string() + ": cannot create the output folder" +
                       (ec ? " (" + ec.message() + ")" : std::string()));
  }
}

// --gnss-noise: the dataset's (accurate) fixes degraded with a receiver error model, so a real
// RTK-grade drive reproduces the reference experiment's SPP-grade GNSS. Returns report.json's
// record of it (null for none).
nlohmann::json degradeGnss(io::Dataset& ds, const std::string& spec, std::uint64_t seed) {
  if (spec == "none") return nullptr;
  const sim::GnssErrorModel model = loadGnssNoiseModel(spec);
  if (ds.gnss.empty()) {
    spdlog::warn("--gnss-noise {}: the dataset has no GNSS fixes to degrade", spec);
    return nullptr;
  }
  const sim::DegradedFixes degraded = sim::degradeFixes(ds.gnss, model, seed);
  ds.gnss = degraded.fixes;
  double sum_sq = 0.0;
  for (const Eigen::Vector3d& e : degraded.added_error_enu) sum_sq += e.squaredNorm();
  const double rms_m = std::sqrt(sum_sq / static_cast<double>(degraded.fixes.size()));
  spdlog::info(
      "--gnss-noise {} (seed {}): {} fixes degraded, added error rms {:.2f} m, {} outliers", spec,
      seed, degraded.fixes.size(), rms_m, degraded.outliers);
  return {{"model", spec},
          {"seed", seed},
          {"white_h_m", model.white_h_m},
          {"white_v_m", model.white_v_m},
          {"bias_m", model.bias_m},
          {"bias_tau_s", model.bias_tau_s},
          {"outlier_probability", model.outlier_probability},
          {"outliers", degraded.outliers},
          {"added_error_rms_m", rms_m}};
}

// No camera frames but an IMU and GNSS: GNSS/INS on the IMU (run/ins_run.hpp) instead of VIO.
int runGnssInsMode(const RunOptions& opt, const CommonOptions& common, const AppConfig& config,
                   const io::Dataset& ds, const nlohmann::json& gnss_noise) {
  const bool dataset_noise = ds.imu_noise && config.imu.prefer_dataset_noise;
  const fusion::InsConfig ins =
      config.fusion.insConfig(dataset_noise ? *ds.imu_noise : config.imu.noise);
  const fs::path out = opt.out;
  makeOutputDir(out);
  spdlog::info("{} {} ({}): no camera frames, {} IMU samples, {} fixes: GNSS/INS",
               io::toString(ds.format), ds.root.string(), ds.variant, ds.imu.size(),
               ds.gnss.size());
  const run::InsRunResult r = run::runGnssIns(ds, ins, config.fusion.originLla());
  run::writeGnssInsOutputs(out, r);
  std::optional<run::InsEvaluation> evaluation;
  if (ds.groundtruth && ds.groundtruth->hasTimestamps() && ds.groundtruth_enu_origin) {
    const Trajectory truth =
        run::reexpressEnu(*ds.groundtruth, *ds.groundtruth_enu_origin, r.origin);
    io::writeTum(out / "groundtruth.tum", truth);  // for gvio render's error view
    evaluation = run::evaluateGnssIns(r, truth);
  }
  run::InsReportContext context;
  context.command_line = common.command_line;
  context.gnss_requested = opt.gnss;
  context.gnss_noise = gnss_noise;
  context.imu_noise_source = dataset_noise ? "dataset" : "config";
  context.peak_rss_mb = run::peakRssMb();
  context.evaluation = evaluation ? &*evaluation : nullptr;
  io::writeTextAtomic(out / "report.json", run::gnssInsReport(ds, r, context).dump(2) + "\n");
  io::writeTextAtomic(out / "config.yaml", dumpConfigYaml(config));
  std::string figures;
  if (evaluation && evaluation->fused_h && evaluation->raw_h) {
    figures = fmt::format(
        "; position rmse vs truth: fused {:.3f} m horizontal / {:.3f} m 3-D, raw fixes {:.3f} / "
        "{:.3f} m",
        evaluation->fused_h->rmse, evaluation->fused_3d->rmse, evaluation->raw_h->rmse,
        evaluation->raw_3d->rmse);
  }
  spdlog::info(
      "GNSS/INS: {} fixes used, {} rejected, {} before init, {} outage(s), time offset {:.3f} +- "
      "{:.3f} s{}; wrote {}",
      r.stats.fixes_used, r.stats.fixes_rejected, r.stats.fixes_before_init, r.stats.outages.size(),
      r.final_state.time_offset_s, r.time_offset_sigma_s, figures, out.string());
  return 0;
}

int runRun(const RunOptions& opt, const CommonOptions& common) {
  checkGnssOption(opt.gnss);
  const std::optional<run::TwoPassSpans> two_pass =
      opt.two_pass ? std::optional(run::parseTwoPass(*opt.two_pass)) : std::nullopt;
  const AppConfig config = opt.config.load();
  io::Dataset ds = io::readDataset(opt.dataset, io::parseDatasetFormat(opt.format), config.dataset);
  for (const auto& w : ds.warnings) spdlog::warn("{}", w);
  const nlohmann::json gnss_noise = degradeGnss(ds, opt.gnss_noise, opt.seed);
  if (run::wantsGnssIns(ds) && opt.gnss != "off") {
    return runGnssInsMode(opt, common, config, ds, gnss_noise);
  }

  odometry::EstimatorConfig estimator = config.vio.estimator;
  estimator.mode = run::chooseVioMode(config.vio.mode, ds);
  const bool dataset_noise = ds.imu_noise && config.imu.prefer_dataset_noise;
  estimator.imu_noise = dataset_noise ? *ds.imu_noise : config.imu.noise;
  estimator.validate();
  const fs::path out = opt.out;
  makeOutputDir(out);
  // auto fuses with the graph when the dataset has fixes; without fixes every mode is pure VIO.
  const bool fuse_gnss = opt.gnss != "off" && !ds.gnss.empty();
  if (!fuse_gnss && (opt.gnss == "kf" || opt.gnss == "graph")) {
    spdlog::warn("--gnss {}: the dataset has no GNSS fixes: pure VIO", opt.gnss);
  }
  const fusion::FusionMode gnss_mode =
      opt.gnss == "kf" ? fusion::FusionMode::kKf : fusion::FusionMode::kGraph;
  spdlog::info("{} {} ({}): {} frames, mode {}", io::toString(ds.format), ds.root.string(),
               ds.variant, ds.frames.size(), odometry::toString(estimator.mode));

  std::optional<Progress> progress;
  std::optional<run::MapRecorder> recorder;
  if (config.map.enabled) recorder.emplace(config.map.map);
  const run::VioRunResult result = run::runVio(
      ds, estimator,
      [&](std::size_t done, std::size_t total) {
        if (!progress) progress.emplace("vio", total, "frames", common.progressStyle());
        progress->update(done);
      },
      recorder ? run::KeyframeFn([&](const run::KeyframeInput& kf) { recorder->addKeyframe(kf); })
               : run::KeyframeFn());
  if (progress) progress->finish();

  if (result.trajectory.empty()) {
    spdlog::warn("the estimator never initialised: trajectory_vio.tum is empty");
    io::writeTextAtomic(out / "trajectory_vio.tum", "");
  } else {
    io::writeTum(out / "trajectory_vio.tum", result.trajectory);
  }
  std::optional<run::EvaluationOutcome> evaluation;
  if (ds.groundtruth && ds.groundtruth->hasTimestamps()) {
    io::writeTum(out / "groundtruth.tum", *ds.groundtruth);  // for gvio render's error view
    evaluation = run::evaluateAgainstTruth(*ds.groundtruth, result.trajectory);
    if (!evaluation->result) spdlog::warn("no evaluation: {}", evaluation->error);
  }
  std::optional<run::GnssRunResult> gnss;
  if (fuse_gnss) {
    gnss = run::fuseGnss(ds, result.trajectory, gnss_mode, config.fusion.fusion,
                         config.fusion.originLla(), odometry::usesImu(estimator.mode));
    if (gnss) run::writeGeoreferencedOutputs(out, *gnss);
  }
  nlohmann::json map_report;
  if (recorder && !recorder->empty()) {
    const Trajectory* fused = gnss && !gnss->fused.empty() ? &gnss->fused : nullptr;
    nlohmann::json two_pass_report;
    if (two_pass) {  // before the build, which frees the keyframes' dense points
      two_pass_report = run::twoPassReport(*recorder, run::mapPoses(*recorder, fused), *two_pass,
                                           ds.frames.front().t_ns);
    }
    const run::MapRunResult map = run::buildAndWriteMap(*recorder, fused, out);
    map_report = run::mapReport(*recorder, map);
    if (two_pass) map_report["two_pass"] = two_pass_report;
    map_report["las"] = map.las;
    recorder.reset();
    spdlog::info("map ({}): {} landmarks, {} dense points, {} occupied voxels", map.frame,
                 map.map.counts.sparse_points, map.map.counts.dense_points,
                 map.map.counts.occupied_leaves);
  } else if (two_pass) {
    spdlog::warn("--two-pass: the run has no map (map.enabled false, or no keyframe)");
  }
  run::ReportContext context;
  context.map = map_report;
  context.command_line = common.command_line;
  context.gnss_requested = opt.gnss;
  context.gnss_noise = gnss_noise;
  if (odometry::usesImu(estimator.mode))
    context.imu_noise_source = dataset_noise ? "dataset" : "config";
  context.peak_rss_mb = run::peakRssMb();
  context.evaluation = evaluation ? &*evaluation : nullptr;
  context.gnss = gnss ? &*gnss : nullptr;
  // Without alignment the truth must be in the same ENU frame: only with an explicit origin.
  std::optional<run::UnalignedOutcome> evaluation_fused, evaluation_fused_online;
  if (gnss && ds.groundtruth && ds.groundtruth->hasTimestamps() && !gnss->fused.empty() &&
      config.fusion.originLla()) {
    evaluation_fused = run::evaluateUnaligned(*ds.groundtruth, gnss->fused);
    if (!gnss->fused_online.empty()) {
      evaluation_fused_online = run::evaluateUnaligned(*ds.groundtruth, gnss->fused_online);
    }
  }
  context.evaluation_fused = evaluation_fused ? &*evaluation_fused : nullptr;
  context.evaluation_fused_online = evaluation_fused_online ? &*evaluation_fused_online : nullptr;
  io::writeTextAtomic(out / "report.json", run::buildReport(ds, result, context).dump(2) + "\n");
  io::writeTextAtomic(out / "config.yaml", dumpConfigYaml(config));

  const run::TimingSummary total = run::summarizeTimings(result.timings.total_ms);
  std::string ape = "no ground truth";
  if (evaluation) {
    ape = evaluation->result
              ? fmt::format("APE (SE3) rmse {:.3f} m over {:.0f} m",
                            evaluation->result->ape_se3.rmse, evaluation->result->path_length_m)
              : "not evaluated";
  }
  if (gnss) {
    std::string fused_ape;
    if (evaluation_fused && evaluation_fused->ape) {
      fused_ape =
          fmt::format(", fused APE (no alignment) rmse {:.3f} m", evaluation_fused->ape->rmse);
      if (evaluation_fused_online && evaluation_fused_online->ape) {
        fused_ape += fmt::format(" smoothed, {:.3f} m online", evaluation_fused_online->ape->rmse);
      }
    }
    spdlog::info("GNSS {}: {} fixes used, {} rejected, {} skipped, {} outage(s){}",
                 fusion::toString(gnss->mode), gnss->stats.fixes_used, gnss->stats.fixes_rejected,
                 gnss->screening.skipped(), gnss->stats.outages.size(), fused_ape);
  }
  spdlog::info(
      "{} frames, {} keyframes, {} poses written, {}, {:.1f} ms/frame (p95 {:.1f}); wrote {}",
      result.counters.frames, result.counters.keyframes, result.trajectory.size(), ape, total.mean,
      total.p95, out.string());
  return 0;
}

}  // namespace

Command addRunCommand(CLI::App& app, const CommonOptions& common) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* sub =
      app.add_subcommand("run", "Visual-inertial odometry over a dataset, written as a run folder");
  sub->add_option("--dataset", opt->dataset,
                  "Dataset folder (KITTI raw drive, EuRoC; comma2k19 CSV: IMU + GNSS without a "
                  "camera runs GNSS/INS)")
      ->required();
  sub->add_option("--format", opt->format, "Dataset format")
      ->check(CLI::IsMember({"auto", "kitti-raw", "euroc", "comma2k19"}))
      ->capture_default_str();
  sub->add_option("--gnss", opt->gnss,
                  "GNSS fusion: auto (graph when the dataset has fixes), off, kf (the reference "
                  "Kalman filter) or graph; without camera frames any mode but off is GNSS/INS")
      ->capture_default_str();
  sub->add_option("--gnss-noise", opt->gnss_noise,
                  "Degrade the dataset's GNSS fixes: none, spp, rtk or a YAML noise-model file "
                  "(reproduces SPP-grade GNSS on an RTK-grade recording)")
      ->capture_default_str();
  sub->add_option("--seed", opt->seed, "Random seed of --gnss-noise")->capture_default_str();
  sub->add_option("--out", opt->out, "Run folder (created if missing; files in it are replaced)")
      ->capture_default_str();
  sub->add_option("--two-pass", opt->two_pass,
                  "T0:T1,T2:T3: two passes over the same place (seconds since the first frame); "
                  "report.json map.two_pass says how well their map points agree");
  opt->config.addTo(*sub);
  return {sub, [opt, &common] { return runRun(*opt, common); }};
}

}  // namespace gvio::cli
