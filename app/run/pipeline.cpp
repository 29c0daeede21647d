#include "run/pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>

#include "odometry/error.hpp"
#include "run/pipeline_stages.hpp"

namespace gvio::run {

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
  if (runGnssInsInstead(state)) return 0;
  runVioStage(state);
  runGnssStage(state);
  runLoopStage(state);
  writeTrajectories(state);
  runMapStage(state);
  writeReport(state);
  return 0;
}

}  // namespace gvio::run
