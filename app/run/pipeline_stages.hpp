#pragma once
// The state gvio run's stages share and the stages themselves (run/pipeline.cpp calls them in
// order). Each stage reads what the earlier ones left in RunState and adds its own part; files are
// written by the stage that produces them, atomically.
#include <chrono>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"
#include "odometry/vio_config.hpp"
#include "run/evaluation.hpp"
#include "run/gnss_run.hpp"
#include "run/loop_run.hpp"
#include "run/map_run.hpp"
#include "run/pipeline.hpp"
#include "run/run_config.hpp"
#include "run/vio_runner.hpp"

namespace gvio::run {

struct RunState {
  RunState(const RunRequest& r, const RunConfig& c) : request(r), config(c) {}
  const RunRequest& request;
  const RunConfig& config;
  std::string stage;  // the stage running, for report.json when the run does not complete
  io::Dataset dataset;
  nlohmann::json gnss_noise;  // report.json's record of the degradation, null for none
  odometry::EstimatorConfig estimator;
  fusion::FusionConfig fusion;   // config.fusion with the VIO noise of the run's VIO mode
  std::string imu_noise_source;  // "dataset" | "config"; empty without an IMU
  std::optional<MapRecorder> map_recorder;
  std::optional<LoopRecorder> loop_recorder;
  VioRunResult vio;
  std::optional<EvaluationOutcome> evaluation;  // the VIO against the truth
  std::optional<GnssRunResult> gnss;
  std::optional<LoopRunResult> loops;
  nlohmann::json loops_report;  // null without loop closure
  Trajectory final_trajectory;  // trajectory.tum: loop-closed and/or fused; empty: VIO only
  bool georeferenced = false;   // final_trajectory is in local ENU
  nlohmann::json map_report;    // null without a map
  // Wall time of the whole command from here, and of each stage done (seconds by stage name),
  // for report.json: the VIO's own wall_s leaves out the reading and the stages after it.
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  nlohmann::json stage_wall_s = nlohmann::json::object();
};

// Creates the run folder (InvalidInput when it cannot).
void makeOutputDir(const std::filesystem::path& out);
// Reads the dataset (warnings logged) and applies --gnss-noise.
void loadDataset(RunState& s);
// Runs GNSS/INS when the dataset has no camera but an IMU and fixes (and --gnss is not off);
// returns false when the dataset is for the VIO stages.
bool runGnssInsInstead(RunState& s);
// The GNSS antenna's lever arm: fusion.lever_arm_b when set (non-zero), else the recording's
// (a ROS 2 bag's /tf_static), else zero.
Eigen::Vector3d gnssLeverArm(const Eigen::Vector3d& configured, const io::Dataset& ds);
// The estimator configuration, the keyframe recorders, the VIO over the whole dataset;
// trajectory_vio.tum (and groundtruth.tum) written.
void runVioStage(RunState& s);
// GNSS fusion of the VIO trajectory when requested and possible.
void runGnssStage(RunState& s);
// Loop detection and the global pose graph (loops.enabled); loops.csv written. A failure inside
// loop closure is reported and the run goes on without it: it never aborts a run.
void runLoopStage(RunState& s);
// trajectory.tum and the georeferenced files from the final trajectory.
void writeTrajectories(RunState& s);
// The map from the final poses (map.* files), with --two-pass.
void runMapStage(RunState& s);
// report.json, config.yaml and the summary log lines.
void writeReport(RunState& s);

}  // namespace gvio::run
