#pragma once
// One drive of a fleet as a task: the `gvio run` command it is, where its run folder and log go,
// and the record of how it ended (OUT/tasks/NAME.json), written by whichever engine ran it (the
// local engine itself, or `gvio fleet-task` inside a Slurm array task) and read back by the fleet.
//
//   OUT/runs/NAME/    the drive's run folder (gvio run --out)
//   OUT/logs/NAME.log its stdout and stderr, every attempt appended
//   OUT/tasks/NAME.json  how the last attempt ended (DriveResult)
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fleet/child_process.hpp"
#include "fleet/drive_list.hpp"

namespace gvio::fleet {

struct FleetPlan {
  std::filesystem::path out_dir;         // absolute: Slurm tasks run elsewhere
  std::filesystem::path gvio;            // the executable every task runs
  std::vector<std::string> common_args;  // --config FILE / --set k=v, before a drive's own
  std::vector<DriveSpec> drives;
  int threads_per_drive = 0;  // gvio run --threads (0: its default)

  [[nodiscard]] std::filesystem::path runDir(std::size_t i) const;
  [[nodiscard]] std::filesystem::path logFile(std::size_t i) const;
  [[nodiscard]] std::filesystem::path taskFile(std::size_t i) const;
  // The drive's whole command line: gvio --no-progress run --dataset D --out RUN [--threads T]
  // COMMON... DRIVE...
  [[nodiscard]] std::vector<std::string> runArgv(std::size_t i) const;
};

// The plan as JSON (OUT/fleet_plan.json, which Slurm tasks read) and back; InputError naming
// `file` for a malformed one.
nlohmann::json planToJson(const FleetPlan& plan);
FleetPlan planFromJson(const nlohmann::json& j, const std::filesystem::path& file);

enum class DriveState { kComplete, kFailed, kInterrupted, kNotRun };
std::string stateName(DriveState state);  // "complete", "failed", ...

struct DriveResult {
  DriveState state = DriveState::kNotRun;
  int exit_code = -1;
  int attempts = 0;
  double wall_s = 0.0;
  double peak_rss_mb = 0.0;
  std::optional<double> ape_m;    // the run's fused APE RMSE (else its VIO APE) where truth exists
  std::string ape_metric;         // which: "evaluation_fused.ape_none" or "evaluation.ape_se3"
  std::string error;              // one line, for a drive that did not complete
  std::vector<std::string> argv;  // the command it ran (a later fleet reruns it when it changed)
};

nlohmann::json resultToJson(const DriveResult& r);
DriveResult resultFromJson(const nlohmann::json& j);

// How an attempt that ended with `exit` after `wall_s` went: complete when it exited 0 and its
// report.json says "complete", its APE read from that report; else failed (or interrupted, for
// SIGINT/SIGTERM) with the log's last error line.
DriveResult describeExit(const FleetPlan& plan, std::size_t i, const ChildExit& exit, double wall_s,
                         int interrupt_signal);

// The record of an earlier attempt, nullopt when there is none or it is unreadable.
std::optional<DriveResult> readTaskRecord(const FleetPlan& plan, std::size_t i);
void writeTaskRecord(const FleetPlan& plan, std::size_t i, const DriveResult& r);

// A drive an earlier fleet completed with the same command (its --threads aside), whose run
// folder still says "complete": it is not run again.
bool alreadyComplete(const FleetPlan& plan, std::size_t i);

// Starts drive i's `gvio run` as a child process (its log gets an attempt header first).
pid_t startDrive(const FleetPlan& plan, std::size_t i, int attempt);

// Runs drive i here, in the foreground (a Slurm array task's body): spawn, wait, record.
// Returns the record written.
DriveResult runDriveHere(const FleetPlan& plan, std::size_t i, int attempt);

}  // namespace gvio::fleet
