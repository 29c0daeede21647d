#pragma once
// The run folder's state in report.json. `gvio run` writes report.json first of all, with status
// "running" (and its PID), and replaces it at the end with the full report, status "complete". A
// run stopped by SIGINT/SIGTERM rewrites it as "interrupted" (signal, stage, frames done), one that
// fails after the folder was started as "failed" (stage, error); a run killed outright (SIGKILL,
// power loss) leaves "running" with a PID that no longer exists. Files the run had not replaced
// yet are an earlier run's: every output is written atomically, so none is ever half-written.
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "run/pipeline_stages.hpp"

namespace gvio::run {

// Thrown at a frame or stage boundary once RunRequest::pending_signal reports a signal.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal);
  [[nodiscard]] int signal() const { return signal_; }

 private:
  int signal_;
};

// "SIGINT", "SIGTERM", or "signal N".
std::string signalName(int signal);

// Throws Interrupted when the user asked the run to stop.
void stopIfInterrupted(const RunState& s);

// Creates the run folder, removes temporaries a killed run left in it (logged) and writes
// report.json with status "running": an unwritable folder fails here, before any work
// (InvalidInput naming it).
void startRunFolder(RunState& s);

// Rewrites report.json for a run that did not complete (status "interrupted" or "failed") with
// `details`; never throws (the run's own error is the one to report).
void markRunIncomplete(const RunState& s, const std::string& status, nlohmann::json details);

}  // namespace gvio::run
