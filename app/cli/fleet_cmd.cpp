// gvio fleet: many drives as `gvio run` jobs (app/fleet/fleet_run.hpp); gvio fleet-task: one
// Slurm array task's body (hidden: the fleet's job script calls it).
#include <spdlog/spdlog.h>

#include "cli/app.hpp"
#include "cli/interrupt.hpp"
#include "fleet/fleet_run.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

struct FleetCliOptions {
  std::string drives, out, engine = "local";
  int jobs = 1;
  ConfigOptions config;
};

struct FleetTaskOptions {
  std::string plan;
  std::size_t index = 0;
  int attempt = 1;
};

int runFleetCommand(const FleetCliOptions& o) {
  fleet::FleetRequest request;
  request.drives_file = o.drives;
  request.out_dir = o.out;
  request.engine = o.engine == "slurm" ? fleet::Engine::kSlurm : fleet::Engine::kLocal;
  request.jobs = o.jobs;
  // Validated here, before any drive starts; every run gets the same file and overrides.
  request.config = o.config.load().fleet;
  if (o.config.file) {
    request.common_args = {"--config", std::filesystem::absolute(*o.config.file).string()};
  }
  for (const auto& s : o.config.overrides)
    request.common_args.insert(request.common_args.end(), {"--set", s});
  const InterruptGuard interrupts(/*restart_calls=*/false);
  request.pending_signal = &InterruptGuard::pending;
  return fleet::runFleet(request).exit_code;
}

}  // namespace

Command addFleetCommand(CLI::App& app) {
  auto o = std::make_shared<FleetCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "fleet", "Run many drives (gvio run each) on this machine or as a Slurm job array");
  sub->add_option("--drives", o->drives,
                  "Drive list: one dataset per line, then that drive's gvio run options")
      ->required();
  sub->add_option("--out", o->out, "Fleet folder: runs/NAME per drive, logs/, fleet.json")
      ->required();
  sub->add_option("--engine", o->engine, "local (child processes) or slurm (sbatch --array)")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  sub->add_option("--jobs", o->jobs,
                  "Drives at once (local: processes sharing the cores; slurm: the array's "
                  "throttle, 0 = no limit)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  o->config.addTo(*sub);
  return {sub, [o] {
            if (o->engine == "local" && o->jobs == 0) {
              throw InvalidInput("--jobs 0 (no limit) is for --engine slurm; give a number");
            }
            return runFleetCommand(*o);
          }};
}

Command addFleetTaskCommand(CLI::App& app) {
  auto o = std::make_shared<FleetTaskOptions>();
  CLI::App* sub = app.add_subcommand("fleet-task", "One drive of a fleet plan (Slurm tasks)");
  sub->group("");  // hidden: written into the fleet's job script, not typed
  sub->add_option("--plan", o->plan, "fleet_plan.json")->required();
  sub->add_option("--index", o->index, "The drive's index in the plan")->required();
  sub->add_option("--attempt", o->attempt, "Attempt number")->check(CLI::Range(1, 100));
  return {sub, [o] { return fleet::runFleetTask(o->plan, o->index, o->attempt); }};
}

}  // namespace gvio::cli
