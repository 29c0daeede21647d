#pragma once
// `gvio fleet`: every drive of a list as one `gvio run`, on this machine or as a Slurm job array,
// failed drives retried, a fleet.json summary. Resumable: a drive whose run folder an earlier
// fleet completed with the same command is not run again.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fleet/fleet_config.hpp"

namespace gvio::fleet {

enum class Engine { kLocal, kSlurm };

struct FleetRequest {
  std::filesystem::path drives_file;
  std::filesystem::path out_dir;
  Engine engine = Engine::kLocal;
  int jobs = 1;                          // drives at once (slurm: 0 = no throttle)
  std::vector<std::string> common_args;  // --config FILE / --set k=v for every drive's run
  FleetConfig config;
  std::function<int()> pending_signal;  // SIGINT/SIGTERM the fleet received, or 0
  std::filesystem::path gvio;           // the gvio each drive runs; empty: this executable
};

struct FleetOutcome {
  int complete = 0, failed = 0, interrupted = 0, reused = 0;
  int exit_code = 0;  // 0 all complete; 2 failures on bad input only; 1 else; 128+signal
  std::filesystem::path summary;  // fleet.json
};

// Throws InvalidInput for a bad list, an unusable out folder or a Slurm submission that failed
// (nothing is left running then); a failed drive is an outcome, never an exception.
FleetOutcome runFleet(const FleetRequest& request);

// The body of one Slurm array task (`gvio fleet-task`): runs drive `index` of the plan file and
// records how it ended. Returns the drive's exit code.
int runFleetTask(const std::filesystem::path& plan_file, std::size_t index, int attempt);

}  // namespace gvio::fleet
