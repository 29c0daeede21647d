// gvio run: visual-inertial odometry over a recorded (or simulated) drive, written as a run folder
// (DESIGN.md section 4). The pipeline and its stages live in app/run (run/pipeline.hpp); this file
// only turns the command line into a run request.
#include <algorithm>
#include <memory>
#include <thread>
#include <vector>

#include "cli/app.hpp"
#include "cli/interrupt.hpp"
#include "run/pipeline.hpp"

namespace gvio::cli {
namespace {

int defaultThreads() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

struct RunOptions {
  std::string dataset;
  std::string format = "auto";
  std::string gnss = "auto";
  std::string gnss_noise = "none";
  std::uint64_t seed = 1;
  std::string out = "out/run";
  std::optional<std::string> two_pass;
  std::optional<std::string> gnss_file;
  std::vector<std::string> calib;
  int threads = defaultThreads();
  ConfigOptions config;
};

int runRun(const RunOptions& opt, const CommonOptions& common) {
  run::checkGnssOption(opt.gnss);
  run::RunRequest request;
  request.two_pass = opt.two_pass ? std::optional(run::parseTwoPass(*opt.two_pass)) : std::nullopt;
  const AppConfig config = opt.config.load();
  request.dataset = opt.dataset;
  request.format = io::parseDatasetFormat(opt.format);
  request.gnss = opt.gnss;
  request.gnss_noise_name = opt.gnss_noise;
  if (opt.gnss_noise != "none") request.gnss_noise = loadGnssNoiseModel(opt.gnss_noise);
  request.seed = opt.seed;
  request.threads = opt.threads;
  if (opt.gnss_file) request.gnss_file = *opt.gnss_file;
  request.calib_files.assign(opt.calib.begin(), opt.calib.end());
  request.out = opt.out;
  request.command_line = common.command_line;
  request.config_yaml = dumpConfigYaml(config);
  auto progress = std::make_shared<std::optional<Progress>>();
  request.progress = [progress, &common](std::size_t done, std::size_t total) {
    if (!*progress) progress->emplace("vio", total, "frames", common.progressStyle());
    (*progress)->update(done);
  };
  request.progress_done = [progress] {
    if (*progress) (*progress)->finish();
  };
  const InterruptGuard interrupts;
  request.pending_signal = &InterruptGuard::pending;
  return run::runPipeline(request, config);
}

}  // namespace

Command addRunCommand(CLI::App& app, const CommonOptions& common) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* sub =
      app.add_subcommand("run", "Visual-inertial odometry over a dataset, written as a run folder");
  sub->add_option(
         "--dataset", opt->dataset,
         "Dataset folder (KITTI raw drive, EuRoC; comma2k19 CSV: IMU + GNSS without a "
         "camera runs GNSS/INS), ROS 1 bag (.bag, with --calib) or ROS 2 bag (folder, .mcap, "
         ".db3; calibration from its CameraInfo and /tf_static, or --calib)")
      ->required();
  sub->add_option("--format", opt->format, "Dataset format")
      ->check(CLI::IsMember({"auto", "kitti-raw", "euroc", "comma2k19", "rosbag", "ros2bag"}))
      ->capture_default_str();
  sub->add_option("--gnss", opt->gnss,
                  "GNSS fusion: auto (graph when the dataset has fixes), off, kf (the reference "
                  "Kalman filter) or graph; without camera frames any mode but off is GNSS/INS")
      ->capture_default_str();
  sub->add_option("--gnss-noise", opt->gnss_noise,
                  "Degrade the dataset's GNSS fixes: none, spp, rtk or a YAML noise-model file "
                  "(reproduces SPP-grade GNSS on an RTK-grade recording)")
      ->capture_default_str();
  sub->add_option("--calib", opt->calib,
                  "Kalibr calibration replacing the dataset's: camchain.yaml (pinhole radtan, "
                  "T_cam_imu, timeshift_cam_imu) and/or imu.yaml (noise densities, random walks)");
  sub->add_option("--gnss-file", opt->gnss_file,
                  "GNSS fixes from this file instead of the dataset's (any format): NMEA 0183, an "
                  "RTKLIB solution (.pos: GPST/UTC, lat/lon/height or ECEF) or CSV "
                  "(#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m)");
  sub->add_option("--seed", opt->seed, "Random seed of --gnss-noise")
      ->capture_default_str()
      ->check(countValidator("SEED"));
  sub->add_option("--out", opt->out, "Run folder (created if missing; files in it are replaced)")
      ->capture_default_str();
  sub->add_option("--two-pass", opt->two_pass,
                  "T0:T1,T2:T3: two passes over the same place (seconds since the first frame); "
                  "report.json map.two_pass says how well their map points agree");
  sub->add_option("--threads", opt->threads,
                  "Threads (default: the machine's cores); any number gives the same outputs, "
                  "bit for bit, 1 runs every stage in turn")
      ->check(CLI::Range(1, 256));  // no "=N" default shown: N is this machine's, not the reader's
  opt->config.addTo(*sub);
  return {sub, [opt, &common] { return runRun(*opt, common); }};
}

}  // namespace gvio::cli
