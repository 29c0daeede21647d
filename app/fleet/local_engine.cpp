// The local engine (engines.hpp): a fixed number of child processes, blocking wait4.
#include <signal.h>

#include <cerrno>
#include <chrono>
#include <map>

#include "fleet/engines.hpp"

namespace gvio::fleet {
namespace {

using Clock = std::chrono::steady_clock;

struct Running {
  std::size_t drive = 0;
  Clock::time_point start;
};

}  // namespace

EngineResults runLocal(const EngineRequest& request) {
  const FleetPlan& plan = *request.plan;
  const std::size_t jobs = static_cast<std::size_t>(std::max(1, request.jobs));
  EngineResults results;
  std::map<pid_t, Running> running;
  std::size_t next = 0;
  int forwarded = 0;
  while (true) {
    const int signal = request.pending_signal ? request.pending_signal() : 0;
    while (signal == 0 && running.size() < jobs && next < request.drives.size()) {
      const std::size_t i = request.drives[next++];
      running[startDrive(plan, i, request.attempt)] = {i, Clock::now()};
    }
    if (signal != 0 && forwarded == 0) {
      // Once: a second signal to the fleet ends it (SA_RESETHAND); the children keep theirs.
      for (const auto& [pid, r] : running) ::kill(pid, signal);
      forwarded = signal;
    }
    if (running.empty()) break;
    const auto exit = waitChild(-1);
    if (!exit) {
      if (errno == EINTR) continue;  // a signal: forwarded at the top of the loop
      break;                         // ECHILD: nothing left (should not happen)
    }
    const auto it = running.find(exit->pid);
    if (it == running.end()) continue;  // not one of ours
    const double wall_s = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    const std::size_t i = it->second.drive;
    running.erase(it);
    DriveResult r = describeExit(plan, i, *exit, wall_s, forwarded);
    r.attempts = request.attempt;
    writeTaskRecord(plan, i, r);
    if (request.on_done) request.on_done(i, r);
    results[i] = r;
  }
  for (; next < request.drives.size(); ++next) {  // never started: the fleet was interrupted
    DriveResult r;
    r.state = DriveState::kNotRun;
    r.error = "not started: the fleet was interrupted";
    r.argv = plan.runArgv(request.drives[next]);
    results[request.drives[next]] = r;
  }
  return results;
}

}  // namespace gvio::fleet
