#pragma once
// Configuration of `gvio fleet` (many drives as jobs) and `gvio merge` (their maps as UTM tiles):
// plain structs with defaults, bound to the YAML keys fleet.* and merge.* in cli/config.cpp.
#include <string>

namespace gvio::fleet {

// What one Slurm array task (one drive's `gvio run`) asks for: sbatch's --cpus-per-task, --mem,
// --time and --partition/--account (empty: the cluster's default).
struct SlurmConfig {
  int cpus_per_task = 2;
  int mem_mb = 4096;  // a KITTI-00-sized drive peaks at about 2 GB (docs/benchmarks/run-time.md)
  int time_limit_min = 120;  // KITTI-00 runs in about 4 minutes on 2 cores
  std::string partition;     // "" = the cluster's default partition
  std::string account;       // "" = the user's default account
  std::string job_name = "gvio-fleet";
};

struct FleetConfig {
  SlurmConfig slurm;
  int retries =
      1;  // a failed drive is run again this many times (not one that failed on bad input)

  void validate() const;  // throws InvalidInput naming the key
};

struct MergeConfig {
  // Bring overlapping drives into agreement first (merge_align.hpp): loops between the drives
  // and one joint pose graph; the drives' maps follow their keyframes.
  bool align = true;
  double tile_size_m = 50.0;            // square UTM tiles (gvio merge --tile-size overrides it)
  double octomap_resolution_m = 0.2;    // leaf size of each tile's .bt
  double max_zone_distance_km = 100.0;  // a run farther than this outside the first run's UTM zone
                                        // is refused rather than reprojected (scale error grows)

  void validate() const;  // throws InvalidInput naming the key
};

}  // namespace gvio::fleet
