#include "run/pipeline.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <chrono>

#include "odometry/error.hpp"
#include "run/pipeline_stages.hpp"
#include "run/run_status.hpp"

namespace gvio::run {
namespace {

struct Stage {
  const char* name;
  void (*run)(RunState&);
};

// The VIO run's stages in order. The user's interrupt is honoured inside the VIO (at a frame)
// and after every stage but the last, so a stopped run has written whole stages only.
constexpr std::array kVioStages = {
    Stage{"vio", runVioStage},    Stage{"gnss", runGnssStage},
    Stage{"loops", runLoopStage}, Stage{"trajectories", writeTrajectories},
    Stage{"map", runMapStage},    Stage{"report", writeReport},
};

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void runStages(RunState& state) {
  state.stage = "gnss_ins";
  if (runGnssInsInstead(state)) return;
  for (const Stage& stage : kVioStages) {
    state.stage = stage.name;
    const Clock::time_point start = Clock::now();
    stage.run(state);
    state.stage_wall_s[stage.name] = secondsSince(start);
    if (&stage != &kVioStages.back()) stopIfInterrupted(state);
  }
}

int stopped(const RunState& state, const Interrupted& e) {
  const bool mid_vio = state.stage == "vio" && state.vio.stopped;
  nlohmann::json details = {{"signal", signalName(e.signal())}, {"stage_completed", !mid_vio}};
  std::string where = "after stage " + state.stage;
  if (mid_vio) {
    details["frames_done"] = state.vio.counters.frames;
    details["frames_total"] = state.dataset.frames.size();
    where = fmt::format("in stage vio after {} of {} frames", state.vio.counters.frames,
                        state.dataset.frames.size());
  }
  markRunIncomplete(state, "interrupted", details);
  spdlog::error("{} {}: {} marks the run incomplete", e.what(), where,
                (state.request.out / "report.json").string());
  return 128 + e.signal();
}

}  // namespace

void checkGnssOption(const std::string& gnss) {
  if (gnss != "auto" && gnss != "off" && gnss != "kf" && gnss != "graph") {
    throw InvalidInput("--gnss '" + gnss + "': expected auto, off, kf or graph");
  }
}

int runPipeline(const RunRequest& request, const RunConfig& config) {
  checkGnssOption(request.gnss);
  // --threads 1: one thread for everything. >= 2: the stages overlap (decoding, the estimator and
  // the keyframe work on a thread each; the map's occupancy beside its clouds) on the first two
  // cores, and OpenCV's pool gets the cores beyond them (1: no pool), never contending with the
  // stages. OpenCV's parallel loops split images into bands with the same per-pixel work, so the
  // pool's size changes no result.
  cv::setNumThreads(std::max(1, request.threads - 2));
  RunState state(request, config);
  loadDataset(state);
  state.stage_wall_s["read"] = secondsSince(state.started);
  if (const int signal = request.pending_signal ? request.pending_signal() : 0; signal != 0) {
    spdlog::error("interrupted by {} while reading the dataset: nothing was written",
                  signalName(signal));
    return 128 + signal;
  }
  startRunFolder(state);
  try {
    runStages(state);
  } catch (const Interrupted& e) {
    return stopped(state, e);
  } catch (const std::exception& e) {
    markRunIncomplete(state, "failed", {{"error", e.what()}});
    throw;
  }
  return 0;
}

}  // namespace gvio::run
