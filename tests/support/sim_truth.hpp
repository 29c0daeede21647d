#pragma once
// The truth a `gvio simulate` KITTI-layout folder records, read with no gvio code: the ENU origin
// and antenna lever arm from sim.yaml (config.sim.*), and the true body lat/lon/h per oxts record
// (oxts/timestamps.txt + oxts/data/*.txt fields 1-3). Also trajectory_lla.csv of a run folder.
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <vector>

namespace gvio::test {

struct LlaSample {
  double t_s = 0.0;  // UTC seconds since 1970 (the dataset clock)
  double lat_deg = 0.0, lon_deg = 0.0, h_m = 0.0;
};

struct SimTruth {
  double origin_lat_deg = 0.0, origin_lon_deg = 0.0, origin_h_m = 0.0;
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();
  std::vector<LlaSample> oxts;  // time-ordered

  // The oxts record nearest to t_s, if within tolerance_s.
  [[nodiscard]] std::optional<LlaSample> bodyAt(double t_s, double tolerance_s) const;
  // "--set fusion.origin=LAT,LON,H --set fusion.lever_arm_b=[X,Y,Z]" for gvio run.
  [[nodiscard]] std::string runOptions() const;
};

// Throws std::runtime_error when sim.yaml lacks a key or an oxts file is malformed.
SimTruth readSimTruth(const std::filesystem::path& dataset);

// trajectory_lla.csv rows (t_s, lat, lon, h); throws std::runtime_error on a malformed row.
std::vector<LlaSample> readTrajectoryLla(const std::filesystem::path& file);

}  // namespace gvio::test
