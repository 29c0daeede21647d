#pragma once
// What a `gvio run --out DIR` folder holds that other commands read back (DESIGN.md section 4).
#include <filesystem>
#include <optional>

#include "odometry/trajectory.hpp"

namespace gvio::io {

struct RunFiles {
  std::filesystem::path dir;
  std::optional<Trajectory> fused;  // trajectory.tum: body in local ENU
  std::optional<Trajectory> vio;    // trajectory_vio.tum: VIO world frame
  std::optional<Trajectory> truth;  // groundtruth.tum (or the --reference file): body in ENU
};

// Reads every trajectory file present. Throws InputError when the folder is missing or holds none
// of trajectory.tum / trajectory_vio.tum, or when a present file is malformed.
RunFiles readRunDir(const std::filesystem::path& dir,
                    const std::optional<std::filesystem::path>& reference = std::nullopt);

}  // namespace gvio::io
