// The Slurm engine (engines.hpp): one job array per attempt, sbatch --wait.
#include <signal.h>

#include <cerrno>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "fleet/engines.hpp"
#include "io/atomic_write.hpp"
#include "odometry/error.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// Single quotes for sh: the plan's paths are the user's.
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

fs::path slurmDir(const FleetPlan& plan) {
  return plan.out_dir / "slurm";
}

// The array task's body: this gvio, in the fleet's out folder (sbatch --chdir), runs the drive
// whose index is the task's.
fs::path writeScript(const EngineRequest& request) {
  const fs::path script = slurmDir(*request.plan) / fmt::format("attempt{}.sh", request.attempt);
  const std::string text = fmt::format(
      "#!/bin/sh\n"
      "# gvio fleet, attempt {}: one array task per drive (written by gvio fleet; the drive's\n"
      "# output goes to logs/NAME.log, how it ended to tasks/NAME.json).\n"
      "exec {} --no-progress fleet-task --plan {} --index \"$SLURM_ARRAY_TASK_ID\" --attempt {}\n",
      request.attempt, shellQuote(request.plan->gvio.string()),
      shellQuote(request.plan_file.string()), request.attempt);
  io::writeTextAtomic(script, text);
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
  return script;
}

fs::path taskOutput(const FleetPlan& plan, int attempt, std::size_t i) {
  return slurmDir(plan) / fmt::format("attempt{}_task{}.out", attempt, i);
}

// The job id sbatch --parsable printed first: "id" or "id;cluster"; "" before it did.
std::string jobIdIn(const fs::path& sbatch_out) {
  std::ifstream in(sbatch_out);
  std::string line;
  std::getline(in, line);
  return line.substr(0, line.find(';'));
}

// scancel of the array job, waited for (a signal to the fleet must not leave tasks queued).
void cancel(const std::string& job_id, const fs::path& log) {
  try {
    const pid_t pid = spawnLogged({"scancel", job_id}, log, std::nullopt, true);
    while (!waitChild(pid) && errno == EINTR) {
    }
  } catch (const InvalidInput&) {
    // scancel missing while sbatch exists: nothing more to do than report the interruption
  }
}

}  // namespace

std::vector<std::string> sbatchArgv(const EngineRequest& request, const SlurmConfig& slurm,
                                    const fs::path& script) {
  std::string indices;
  for (const std::size_t i : request.drives)
    indices += (indices.empty() ? "" : ",") + std::to_string(i);
  if (request.jobs > 0) indices += "%" + std::to_string(request.jobs);
  std::vector<std::string> argv{
      "sbatch", "--parsable", "--wait", "--array=" + indices, "--job-name=" + slurm.job_name,
      "--cpus-per-task=" + std::to_string(slurm.cpus_per_task),
      "--mem=" + std::to_string(slurm.mem_mb) + "M",
      "--time=" + std::to_string(slurm.time_limit_min), "--chdir=" + request.plan->out_dir.string(),
      // %a: the array index (= the drive's index in the plan).
      "--output=" + (slurmDir(*request.plan) / fmt::format("attempt{}_task%a.out", request.attempt))
                        .string()};
  if (!slurm.partition.empty()) argv.push_back("--partition=" + slurm.partition);
  if (!slurm.account.empty()) argv.push_back("--account=" + slurm.account);
  argv.push_back(script.string());
  return argv;
}

SlurmSubmission runSlurm(const EngineRequest& request, const SlurmConfig& slurm) {
  const FleetPlan& plan = *request.plan;
  fs::create_directories(slurmDir(plan));
  // A record left by an earlier attempt must not pass for this one's.
  for (const std::size_t i : request.drives) fs::remove(plan.taskFile(i));
  const fs::path script = writeScript(request);
  const fs::path out = slurmDir(plan) / fmt::format("attempt{}_sbatch.out", request.attempt);
  const fs::path err = slurmDir(plan) / fmt::format("attempt{}_sbatch.err", request.attempt);
  fs::remove(out);
  fs::remove(err);
  pid_t pid = 0;
  try {
    pid = spawnLogged(sbatchArgv(request, slurm, script), out, err, true);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("slurm engine: ") + e.what() +
                       " (is Slurm installed and sbatch in PATH?)");
  }
  std::optional<ChildExit> exit;
  bool cancelled = false;
  while (!(exit = waitChild(pid))) {
    if (errno != EINTR) throw std::runtime_error("lost the sbatch process");
    const int signal = request.pending_signal ? request.pending_signal() : 0;
    const std::string job = signal != 0 && !cancelled ? jobIdIn(out) : std::string();
    if (!job.empty()) {
      cancel(job, slurmDir(plan) / "scancel.log");
      cancelled = true;
    }
  }
  SlurmSubmission submission;
  submission.job_id = jobIdIn(out);
  if (submission.job_id.empty()) {
    std::string why = lastErrorLine(err);
    if (why.empty()) why = fmt::format("sbatch exited with code {}", exit->exit_code);
    throw InvalidInput("slurm engine: the job was not submitted: " + why);
  }
  for (const std::size_t i : request.drives) {
    if (auto record = readTaskRecord(plan, i); record && record->attempts == request.attempt) {
      submission.results[i] = *record;
      continue;
    }
    DriveResult r;
    r.argv = plan.runArgv(i);
    r.attempts = request.attempt;
    r.state = cancelled ? DriveState::kInterrupted : DriveState::kFailed;
    std::string why = lastErrorLine(taskOutput(plan, request.attempt, i));
    if (why.empty()) why = "no output (cancelled before it started?)";
    r.error = fmt::format("Slurm task {}_{} left no record: {}", submission.job_id, i, why);
    submission.results[i] = r;
  }
  return submission;
}

}  // namespace gvio::fleet
