#pragma once
// gvio run's GNSS stage: screens the dataset's fixes, fuses them with the VIO trajectory
// (fusion::GnssFusion, causal: replaying the recorded VIO poses in time order gives what an
// interleaved online run gives), and turns the result into the run folder's georeferenced files
// (trajectory.tum, trajectory_lla.csv, georef.json) and report.json fields.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "fusion/gnss_fusion.hpp"
#include "fusion/gnss_screening.hpp"
#include "io/dataset.hpp"

namespace gvio::run {

struct GnssRunResult {
  fusion::FusionMode mode = fusion::FusionMode::kGraph;
  fusion::Lla origin;  // of the local ENU frame
  fusion::ScreeningCounts screening;
  fusion::FusionStats stats;
  // T_enu_b, empty when the registration to ENU never succeeded: the smoothed trajectory when the
  // smoothing pass ran (graph mode), else the causal one.
  Trajectory fused;
  Trajectory fused_online;  // the causal T_enu_b, when `fused` is not the causal one
  bool smoothed = false;    // the smoothing pass ran (graph mode)
  std::vector<fusion::PoseCovariance> fused_covariance;  // per smoothed pose, may be empty
  std::optional<Eigen::Isometry3d> T_enu_w;
};

// nullopt when the dataset has no usable fix (the run stays pure VIO). `origin` nullopt: the first
// usable fix. `has_imu`: the VIO world is gravity-aligned (register yaw only), else full rotation.
std::optional<GnssRunResult> fuseGnss(const io::Dataset& dataset, const Trajectory& vio,
                                      fusion::FusionMode mode, fusion::FusionConfig config,
                                      const std::optional<fusion::Lla>& origin, bool has_imu);

// gnss_fixes.csv: every screened fix in local ENU with what became of it
// ("t_s,e_m,n_m,u_m,status", status used | rejected | unmatched | unaligned).
void writeGnssFixes(const std::filesystem::path& file, const GnssRunResult& result);

// trajectory_lla.csv: `t_s,lat_deg,lon_deg,h_ellipsoid_m,qw,qx,qy,qz` of the body poses T_enu_b in
// the local ENU frame at `origin` (shared with the GNSS/INS run).
void writeTrajectoryLla(const std::filesystem::path& file, const Trajectory& T_enu_b,
                        const fusion::Lla& origin);

// georef.json's common part: the ENU origin (EPSG:4979), its UTM zone / EPSG and easting/northing,
// and the enu and body frames; each run adds its own frames, heights and time base.
nlohmann::json georefJson(const fusion::Lla& origin);

// gnss_fixes.csv, and when the fusion registered: trajectory.tum (T_enu_b), trajectory_lla.csv (t,
// lat, lon, h, qw qx qy qz of the body in ENU), georef.json and, when trajectory.tum is the
// smoothed one, trajectory_online.tum (causal) and trajectory_cov.csv (each smoothed pose's
// covariance), all atomically.
void writeGeoreferencedOutputs(const std::filesystem::path& out, const GnssRunResult& result);

// report.json's "gnss" object and "outages" array.
nlohmann::json gnssReport(const GnssRunResult& result, std::size_t fixes_in_dataset);
nlohmann::json outagesReport(const GnssRunResult& result);

}  // namespace gvio::run
