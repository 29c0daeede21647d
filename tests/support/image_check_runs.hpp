#pragma once
// Run folders for `gvio consistency --images` tests: a run folder is its report.json's sources and
// a trajectory (the check rebuilds the map from it), so a test checks any trajectory over a
// simulated drive without a gvio run, e.g. the true poses with a stretch moved.
#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/fixtures.hpp"

namespace gvio::test {

// The TUM file `tum` with its positions moved by `offset` between t0 and t1 s from its start.
inline std::string displacedTum(const std::filesystem::path& tum, double t0, double t1,
                                const Eigen::Vector3d& offset) {
  std::ifstream in(tum);
  std::ostringstream out;
  std::string line;
  double first = std::nan("");
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double t = 0, x = 0, y = 0, z = 0, qx = 0, qy = 0, qz = 0, qw = 0;
    ls >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    if (std::isnan(first)) first = t;
    if (t - first >= t0 && t - first < t1) {
      x += offset.x();
      y += offset.y();
      z += offset.z();
    }
    out << fmt::format("{:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", t, x, y, z, qx,
                       qy, qz, qw);
  }
  return out.str();
}

// A run folder `dir` over the simulated `dataset` whose trajectory.tum is `trajectory_tum` (text).
inline void writeTrajectoryRun(const std::filesystem::path& dir,
                               const std::filesystem::path& dataset,
                               const std::string& trajectory_tum) {
  std::filesystem::create_directories(dir);
  const nlohmann::json r = {{"mode", "stereo-imu"},
                            {"sources",
                             {{"dataset", std::filesystem::absolute(dataset).string()},
                              {"format", "kitti-raw"},
                              {"calib_files", nlohmann::json::array()},
                              {"gnss_file", nullptr}}}};
  writeText(dir / "report.json", r.dump(2));
  writeText(dir / "trajectory.tum", trajectory_tum);
}

}  // namespace gvio::test
