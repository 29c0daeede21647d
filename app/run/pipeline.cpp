#include "run/pipeline.hpp"

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
