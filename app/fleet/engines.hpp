#pragma once
// The two ways `gvio fleet` runs its drives. Both take the drives still to do, run each once and
// leave a record per drive (drive_task.hpp); the fleet decides what to retry.
//
// local: up to `jobs` child processes of this machine at a time, reaped with wait4 (blocking: no
//   polling), each in its own process group; a SIGINT/SIGTERM to the fleet is passed on to them
//   once, so that each run stops at its next frame and marks its folder interrupted.
// slurm: one job array (sbatch --array=LIST%jobs --wait), one task per drive running
//   `gvio fleet-task`, which runs the drive and writes its record; sbatch --wait returns when every
//   task has ended (sbatch waits on the controller, we wait on sbatch). A signal cancels the job
//   (scancel). A task that left no record (cancelled, past its time limit, node failure) is a
//   failed drive with Slurm's last line as its error.
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fleet/drive_task.hpp"
#include "fleet/fleet_config.hpp"

namespace gvio::fleet {

struct EngineRequest {
  const FleetPlan* plan = nullptr;
  std::filesystem::path plan_file;  // the plan as JSON (the Slurm tasks read it)
  std::vector<std::size_t> drives;  // indices into plan->drives
  int jobs = 1;                     // at once (slurm: the array's throttle; 0 = no limit)
  int attempt = 1;
  std::function<int()> pending_signal;                           // SIGINT/SIGTERM received, or 0
  std::function<void(std::size_t, const DriveResult&)> on_done;  // as each drive ends (local)
};

using EngineResults = std::map<std::size_t, DriveResult>;

EngineResults runLocal(const EngineRequest& request);

struct SlurmSubmission {
  std::string job_id;  // the array job's id
  EngineResults results;
};

// Throws InvalidInput with sbatch's own message when the job cannot be submitted (sbatch missing,
// controller unreachable, a partition that does not exist, ...).
SlurmSubmission runSlurm(const EngineRequest& request, const SlurmConfig& slurm);

// sbatch's arguments for `request` (exposed for tests).
std::vector<std::string> sbatchArgv(const EngineRequest& request, const SlurmConfig& slurm,
                                    const std::filesystem::path& script);

}  // namespace gvio::fleet
