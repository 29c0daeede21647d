#pragma once
// What a `gvio run --out DIR` folder holds that other commands read back (DESIGN.md section 4):
// trajectories, the map (map.pcd, map.ot / map.bt), the GNSS fixes as the run judged them
// (gnss_fixes.csv), the GNSS outages (report.json) and the loop-closure candidates (loops.csv).
// Every file is optional except one trajectory; a view draws what exists.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/loops_csv.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

// map.pcd: landmark and dense points in local ENU (float32, as the file stores them).
struct MapCloud {
  std::vector<Eigen::Vector3f> p_enu;
  std::vector<float> intensity;      // 0..255, one per point; empty when the file has none
  std::vector<std::uint8_t> source;  // 0 sparse landmark, 1 dense stereo; empty when absent
  static constexpr std::uint8_t kSparse = 0, kDense = 1;
};

// One occupied OctoMap leaf (pruned leaves are larger than the resolution).
struct OccupiedVoxel {
  Eigen::Vector3f center_enu;
  float size_m = 0.0F;
  std::array<std::uint8_t, 3> rgb{255, 255, 255};  // ColorOcTree colour; white for an OcTree
};

// map.ot (ColorOcTree or OcTree) or map.bt (OcTree): its occupied leaves only.
struct OccupancyMap {
  std::filesystem::path file;
  double resolution_m = 0.0;
  bool has_color = false;  // a ColorOcTree
  std::vector<OccupiedVoxel> voxels;
};

// What the run did with a fix: fused it, rejected it at the outlier gate, or never got to fuse it
// (screened out as invalid, outside the VIO trajectory, or no ENU registration).
enum class FixStatus { kUsed, kRejected, kSkipped, kUnmatched, kUnaligned };

// gnss_fixes.csv: each fix in local ENU and what the fusion did with it. Fixes that were not
// fused may hold non-finite coordinates.
struct GnssFixRecord {
  double t_s = 0.0;
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  FixStatus status = FixStatus::kUsed;
};

struct TimeSpan {  // seconds on the dataset clock (the trajectories' stamps)
  double t0_s = 0.0, t1_s = 0.0;
};

struct RunFiles {
  std::filesystem::path dir;
  std::optional<Trajectory> fused;        // trajectory.tum: body in local ENU
  std::optional<Trajectory> vio;          // trajectory_vio.tum: VIO world frame
  std::optional<Trajectory> truth;        // groundtruth.tum (or the --reference file): body in ENU
  std::optional<MapCloud> cloud;          // map.pcd
  std::optional<OccupancyMap> occupancy;  // map.ot, else map.bt
  std::optional<std::vector<GnssFixRecord>> gnss_fixes;  // gnss_fixes.csv
  std::vector<TimeSpan> outages;                         // report.json "outages"
  std::optional<std::vector<LoopCsvRow>> loops;          // loops.csv
};

struct RunReadOptions {
  std::optional<std::filesystem::path> reference;  // truth file instead of groundtruth.tum
  bool cloud = true;       // read map.pcd when present (large: skip it when not drawn)
  bool occupancy = true;   // read map.ot / map.bt when present
  bool gnss_fixes = true;  // read gnss_fixes.csv when present
  bool outages = true;     // read report.json's outages when present
  bool loops = true;       // read loops.csv when present
};

// A JSON file whose top level is an object (report.json); InputError naming the file (and the
// line of a syntax error) else.
nlohmann::json readJsonObject(const std::filesystem::path& file);

// A warning when `dir`/report.json says its run did not complete (status "running",
// "interrupted" or "failed": gvio run's run/run_status.hpp), so files it had not replaced yet may
// be an earlier run's; nullopt for a complete run, no report or an unreadable one (the readers
// that need it report that).
std::optional<std::string> incompleteRunWarning(const std::filesystem::path& dir);

// Reads every file present (the map files as `options` asks). Throws InputError when the folder
// is missing or holds neither trajectory.tum nor trajectory_vio.tum, or when a present file is
// malformed (naming the file and, for text files, the line).
RunFiles readRunDir(const std::filesystem::path& dir, const RunReadOptions& options);
RunFiles readRunDir(const std::filesystem::path& dir,
                    const std::optional<std::filesystem::path>& reference = std::nullopt);

// The readers behind readRunDir, one file each; InputError on malformed content.
MapCloud readMapCloud(const std::filesystem::path& pcd_file);
OccupancyMap readOccupancy(const std::filesystem::path& octomap_file);  // .ot or .bt
std::vector<GnssFixRecord> readGnssFixes(const std::filesystem::path& csv_file);
std::vector<TimeSpan> readOutages(const std::filesystem::path& report_json);

}  // namespace gvio::io
