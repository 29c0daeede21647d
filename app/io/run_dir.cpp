#include "io/run_dir.hpp"

#include "io/input_error.hpp"
#include "io/trajectory_io.hpp"

namespace gvio::io {
namespace fs = std::filesystem;

RunFiles readRunDir(const fs::path& dir, const std::optional<fs::path>& reference) {
  if (!fs::is_directory(dir)) throw InputError(dir, 0, "run folder not found");
  RunFiles run;
  run.dir = dir;
  auto optionalTum = [](const fs::path& file) -> std::optional<Trajectory> {
    if (!fs::exists(file)) return std::nullopt;
    return readTum(file);
  };
  run.fused = optionalTum(dir / "trajectory.tum");
  run.vio = optionalTum(dir / "trajectory_vio.tum");
  if (!run.fused && !run.vio) {
    throw InputError(dir, 0, "no trajectory.tum or trajectory_vio.tum in the run folder");
  }
  run.truth = reference ? std::optional<Trajectory>(
                              readTrajectory(*reference, detectTrajectoryFormat(*reference)))
                        : optionalTum(dir / "groundtruth.tum");
  return run;
}

}  // namespace gvio::io
