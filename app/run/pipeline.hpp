#pragma once
// gvio run's pipeline (DESIGN.md section 1): a dataset in, a run folder out (section 4), as named
// stages over one run state: dataset -> GNSS degradation -> VIO (keyframes recorded for the map
// and for loop closure) -> GNSS fusion -> loop closure + global pose graph -> trajectories ->
// map -> report. A dataset with an IMU and GNSS but no camera runs GNSS/INS instead of the VIO
// stages. app/cli turns the command line into a RunRequest and nothing more.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "run/map_passes.hpp"
#include "run/run_config.hpp"
#include "run/vio_runner.hpp"
#include "sim/gnss_error.hpp"

namespace gvio::run {

struct RunRequest {
  std::filesystem::path dataset;
  std::optional<io::DatasetFormat> format;  // nullopt: detect
  std::string gnss = "auto";                // auto | off | kf | graph
  // --gnss-noise: its name as given (none, spp, rtk, a file) and the model behind it.
  std::string gnss_noise_name = "none";
  std::optional<sim::GnssErrorModel> gnss_noise;
  std::uint64_t seed = 1;                          // of the GNSS degradation
  std::optional<std::filesystem::path> gnss_file;  // --gnss-file: replaces the dataset's fixes
  std::vector<std::filesystem::path> calib_files;  // --calib: Kalibr camchain / imu files
  std::filesystem::path out;
  std::optional<TwoPassSpans> two_pass;
  // --threads: 1 runs every stage in order on one thread; >= 2 overlaps them (decoding ahead of
  // the estimator, keyframe work and the map's stages beside it) with the same outputs.
  int threads = 1;
  std::string command_line;  // report.json
  std::string config_yaml;   // the effective configuration, written as config.yaml
  ProgressFn progress;       // VIO frames done / total; may be empty
  // The signal (SIGINT, SIGTERM) that asks the run to stop, 0 while none; may be empty. Polled
  // at every frame and stage boundary (run/run_status.hpp).
  std::function<int()> pending_signal;
  std::function<void()> progress_done;
};

// "auto", "off", "kf" or "graph"; else InvalidInput naming --gnss.
void checkGnssOption(const std::string& gnss);

// Runs every stage and writes the run folder; returns the exit code (0, or 128 + the signal
// when interrupted: 130 for SIGINT, 143 for SIGTERM). Throws InvalidInput (or io::InputError) for
// bad input, naming the file and line; report.json then says the run failed.
int runPipeline(const RunRequest& request, const RunConfig& config);

}  // namespace gvio::run
