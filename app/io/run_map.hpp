#pragma once
// The run-folder readers that the views of a run's map share (`gvio render --view camera`,
// `gvio render --video`, `gvio consistency --images`): the trajectory the map is expressed along,
// the run's map files, and the dataset reopened as the run opened it.
#include <filesystem>
#include <optional>
#include <string>

#include "io/dataset.hpp"
#include "io/reader_config.hpp"
#include "io/run_dir.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

// The trajectory map.pcd is expressed along: trajectory.tum, else trajectory_vio.tum.
// InvalidInput naming the folder when it has neither.
const Trajectory& mapTrajectory(const RunFiles& run);

// Throws InputError naming the run's folder when its map trajectory has no timestamps (a view at
// an instant cannot be placed on it).
void requireMapTimestamps(const RunFiles& run);

// The run's trajectories and (with_cloud) map.pcd, not the occupancy, fixes, outages or loops;
// warns when the run did not complete. InputError when the trajectory has no timestamps.
RunFiles readMapRun(const std::filesystem::path& run_dir, bool with_cloud = true);

// The dataset as the run opened it (report.json "sources", read with `reader`: the run's
// config.yaml reader settings); `dataset` overrides the recorded sources. `mode` gets the run's
// VIO mode. InputError naming report.json when it records no sources and none is given.
Dataset reopenRunDataset(const std::filesystem::path& run_dir,
                         const std::optional<std::filesystem::path>& dataset,
                         const ReaderConfig& reader, std::string& mode);

}  // namespace gvio::io
