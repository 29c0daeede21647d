#include "fleet/fleet_config.hpp"

#include <fmt/format.h>

#include <cmath>

#include "odometry/error.hpp"

namespace gvio::fleet {
namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw InvalidInput("config: " + message);
}

// Slurm names (partition, account, job name) go onto sbatch's command line: one plain word each.
bool plainWord(const std::string& s) {
  for (const char c : s) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

void FleetConfig::validate() const {
  require(slurm.cpus_per_task >= 1 && slurm.cpus_per_task <= 1024,
          fmt::format("fleet.slurm.cpus_per_task must be 1..1024, got {}", slurm.cpus_per_task));
  require(slurm.mem_mb >= 64,
          fmt::format("fleet.slurm.mem_mb must be at least 64, got {}", slurm.mem_mb));
  require(
      slurm.time_limit_min >= 1,
      fmt::format("fleet.slurm.time_limit_min must be at least 1, got {}", slurm.time_limit_min));
  require(plainWord(slurm.partition),
          "fleet.slurm.partition must be one word (letters, digits, _ - .), got '" +
              slurm.partition + "'");
  require(plainWord(slurm.account),
          "fleet.slurm.account must be one word (letters, digits, _ - .), "
          "got '" +
              slurm.account + "'");
  require(!slurm.job_name.empty() && plainWord(slurm.job_name),
          "fleet.slurm.job_name must be one word (letters, digits, _ - .), got '" + slurm.job_name +
              "'");
  require(retries >= 0 && retries <= 10,
          fmt::format("fleet.retries must be 0..10, got {}", retries));
}

void MergeConfig::validate() const {
  require(tile_size_m >= 1.0 && tile_size_m <= 10000.0,
          fmt::format("merge.tile_size_m must be 1..10000, got {}", tile_size_m));
  require(octomap_resolution_m >= 0.01 && octomap_resolution_m <= tile_size_m,
          fmt::format("merge.octomap_resolution_m must be 0.01..tile_size_m, got {}",
                      octomap_resolution_m));
  require(max_zone_distance_km >= 0.0 && max_zone_distance_km <= 1000.0,
          fmt::format("merge.max_zone_distance_km must be 0..1000, got {}", max_zone_distance_km));
}

}  // namespace gvio::fleet
