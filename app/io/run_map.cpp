#include "io/run_map.hpp"

#include <spdlog/spdlog.h>

#include "io/dataset_sources.hpp"
#include "io/input_error.hpp"
#include "io/run_sources.hpp"
#include "odometry/error.hpp"

namespace gvio::io {
namespace fs = std::filesystem;

const Trajectory& mapTrajectory(const RunFiles& run) {
  if (run.fused && !run.fused->empty()) return *run.fused;
  if (run.vio && !run.vio->empty()) return *run.vio;
  throw InvalidInput(run.dir.string() + ": no trajectory to place the camera on");
}

RunFiles readMapRun(const fs::path& run_dir, bool with_cloud) {
  if (const auto warning = incompleteRunWarning(run_dir)) spdlog::warn("{}", *warning);
  RunReadOptions read;
  read.cloud = with_cloud;
  read.occupancy = read.gnss_fixes = read.outages = read.loops = false;
  RunFiles run = readRunDir(run_dir, read);
  requireMapTimestamps(run);
  return run;
}

void requireMapTimestamps(const RunFiles& run) {
  if (!mapTrajectory(run).hasTimestamps()) {
    throw InputError(run.dir, 0, "the trajectory has no timestamps");
  }
}

Dataset reopenRunDataset(const fs::path& run_dir, const std::optional<fs::path>& dataset,
                         const ReaderConfig& reader, std::string& mode) {
  const fs::path report = run_dir / "report.json";
  const RunSources recorded = readRunSources(report);
  mode = recorded.mode;
  if (!recorded.dataset && !dataset) {
    throw InputError(report, 0,
                     "no \"sources\" (a run by an older gvio): name the dataset with --dataset");
  }
  DatasetSources sources = recorded.dataset.value_or(DatasetSources{});
  if (dataset) {
    sources.dataset = *dataset;
    sources.format.reset();
  }
  return openDataset(sources, reader);
}

}  // namespace gvio::io
