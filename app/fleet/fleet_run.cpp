#include "fleet/fleet_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "fleet/engines.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

struct DriveOutcome {
  DriveResult result;
  bool reused = false;
};

FleetPlan makePlan(const FleetRequest& request) {
  FleetPlan plan;
  plan.out_dir = fs::absolute(request.out_dir).lexically_normal();
  plan.gvio = request.gvio.empty() ? selfExecutable() : fs::absolute(request.gvio);
  plan.common_args = request.common_args;
  plan.drives = readDriveList(request.drives_file);
  if (request.engine == Engine::kLocal) {
    // The machine's cores shared out (gvio run's output does not depend on its thread count).
    const int cores = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
    plan.threads_per_drive = std::max(1, cores / std::max(1, request.jobs));
  } else {
    plan.threads_per_drive = request.config.slurm.cpus_per_task;
  }
  return plan;
}

// A drive worth another attempt: it failed, and not on input it will fail on again (exit 2).
bool retryable(const DriveResult& r) {
  return r.state == DriveState::kFailed && r.exit_code != 2;
}

EngineResults runOnce(const FleetRequest& request, const FleetPlan& plan, const fs::path& plan_file,
                      const std::vector<std::size_t>& todo, int attempt,
                      std::vector<std::string>& slurm_jobs) {
  EngineRequest e;
  e.plan = &plan;
  e.plan_file = plan_file;
  e.drives = todo;
  e.jobs = request.jobs;
  e.attempt = attempt;
  e.pending_signal = request.pending_signal;
  e.on_done = [&plan](std::size_t i, const DriveResult& r) {
    spdlog::info("fleet: {} {} in {:.1f} s", plan.drives[i].name, stateName(r.state), r.wall_s);
  };
  if (request.engine == Engine::kLocal) return runLocal(e);
  spdlog::info("fleet: submitting {} drive(s) to Slurm (attempt {})", todo.size(), attempt);
  SlurmSubmission s = runSlurm(e, request.config.slurm);
  slurm_jobs.push_back(s.job_id);
  for (const auto& [i, r] : s.results) e.on_done(i, r);
  return s.results;
}

nlohmann::json summaryJson(const FleetRequest& request, const FleetPlan& plan,
                           const std::vector<DriveOutcome>& outcomes, double wall_s,
                           const std::vector<std::string>& slurm_jobs, const FleetOutcome& o) {
  nlohmann::json drives = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.drives.size(); ++i) {
    const DriveSpec& d = plan.drives[i];
    const DriveResult& r = outcomes[i].result;
    nlohmann::json j = resultToJson(r);
    j.erase("argv");
    j["name"] = d.name;
    j["list_line"] = d.line;
    j["dataset"] = d.dataset.string();
    j["run_dir"] = plan.runDir(i).string();
    j["log"] = plan.logFile(i).string();
    j["reused"] = outcomes[i].reused;
    drives.push_back(j);
  }
  nlohmann::json j{{"engine", request.engine == Engine::kLocal ? "local" : "slurm"},
                   {"jobs", request.jobs},
                   {"drives_file", fs::absolute(request.drives_file).string()},
                   {"out_dir", plan.out_dir.string()},
                   {"wall_s", wall_s},
                   {"complete", o.complete},
                   {"failed", o.failed},
                   {"interrupted", o.interrupted},
                   {"reused", o.reused},
                   {"exit_code", o.exit_code},
                   {"drives", drives}};
  if (!slurm_jobs.empty()) j["slurm_jobs"] = slurm_jobs;
  return j;
}

FleetOutcome tally(const std::vector<DriveOutcome>& outcomes, int signal) {
  FleetOutcome o;
  bool internal = false;
  for (const auto& d : outcomes) {
    o.reused += d.reused ? 1 : 0;
    switch (d.result.state) {
      case DriveState::kComplete:
        ++o.complete;
        break;
      case DriveState::kFailed:
        ++o.failed;
        internal = internal || d.result.exit_code != 2;
        break;
      case DriveState::kInterrupted:
      case DriveState::kNotRun:
        ++o.interrupted;
        break;
    }
  }
  if (signal != 0) {
    o.exit_code = 128 + signal;
  } else if (o.failed > 0) {
    o.exit_code = internal ? 1 : 2;
  }
  return o;
}

}  // namespace

FleetOutcome runFleet(const FleetRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  request.config.validate();
  FleetPlan plan = makePlan(request);
  std::error_code ec;
  fs::create_directories(plan.out_dir, ec);
  if (ec || !fs::is_directory(plan.out_dir)) {
    throw InvalidInput("--out " + request.out_dir.string() + ": cannot create the folder (" +
                       ec.message() + ")");
  }
  const fs::path plan_file = plan.out_dir / "fleet_plan.json";
  io::writeTextAtomic(plan_file, planToJson(plan).dump(2) + "\n");

  std::vector<DriveOutcome> outcomes(plan.drives.size());
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < plan.drives.size(); ++i) {
    if (alreadyComplete(plan, i)) {
      outcomes[i] = {*readTaskRecord(plan, i), true};
      spdlog::info("fleet: {} already complete ({}), not run again", plan.drives[i].name,
                   plan.runDir(i).string());
    } else {
      todo.push_back(i);
    }
  }
  std::vector<std::string> slurm_jobs;
  for (int attempt = 1; !todo.empty() && attempt <= 1 + request.config.retries; ++attempt) {
    if (attempt > 1) {
      spdlog::warn("fleet: retrying {} failed drive(s) (attempt {})", todo.size(), attempt);
    }
    const EngineResults results = runOnce(request, plan, plan_file, todo, attempt, slurm_jobs);
    std::vector<std::size_t> again;
    for (const auto& [i, r] : results) {
      outcomes[i].result = r;
      if (retryable(r)) again.push_back(i);
    }
    if (request.pending_signal && request.pending_signal() != 0) break;
    todo = again;
  }
  const int signal = request.pending_signal ? request.pending_signal() : 0;
  FleetOutcome o = tally(outcomes, signal);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.summary = plan.out_dir / "fleet.json";
  io::writeTextAtomic(o.summary,
                      summaryJson(request, plan, outcomes, wall_s, slurm_jobs, o).dump(2) + "\n");
  for (std::size_t i = 0; i < plan.drives.size(); ++i) {
    const DriveResult& r = outcomes[i].result;
    if (r.state == DriveState::kFailed) {
      spdlog::error("fleet: {} ({}:{}) failed: {}", plan.drives[i].name,
                    request.drives_file.string(), plan.drives[i].line, r.error);
    }
  }
  spdlog::info("fleet: {} of {} drive(s) complete ({} reused), {} failed, {} interrupted; {}",
               o.complete, plan.drives.size(), o.reused, o.failed, o.interrupted,
               o.summary.string());
  return o;
}

int runFleetTask(const fs::path& plan_file, std::size_t index, int attempt) {
  const FleetPlan plan = planFromJson(io::readJsonObject(plan_file), plan_file);
  if (index >= plan.drives.size()) {
    throw io::InputError(plan_file, 0,
                         fmt::format("no drive {} (the plan has {})", index, plan.drives.size()));
  }
  const DriveResult r = runDriveHere(plan, index, attempt);
  spdlog::info("fleet-task: {} {} (exit {}) in {:.1f} s", plan.drives[index].name,
               stateName(r.state), r.exit_code, r.wall_s);
  if (r.state != DriveState::kComplete) spdlog::error("{}", r.error);
  return r.exit_code;
}

}  // namespace gvio::fleet
