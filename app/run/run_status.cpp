#include "run/run_status.hpp"

#include <unistd.h>

#include <spdlog/spdlog.h>
#include <csignal>

#include "io/atomic_write.hpp"

namespace gvio::run {
namespace {

nlohmann::json baseReport(const RunState& s, const std::string& status) {
  return {{"gvio_version", GVIO_VERSION},
          {"command_line", s.request.command_line},
          {"status", status},
          {"pid", static_cast<long>(::getpid())},
          {"stage", s.stage.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.stage)}};
}

}  // namespace

Interrupted::Interrupted(int signal)
    : std::runtime_error("interrupted by " + signalName(signal)), signal_(signal) {}

std::string signalName(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

void stopIfInterrupted(const RunState& s) {
  if (!s.request.pending_signal) return;
  if (const int signal = s.request.pending_signal(); signal != 0) throw Interrupted(signal);
}

void startRunFolder(RunState& s) {
  const std::filesystem::path& out = s.request.out;
  makeOutputDir(out);
  for (const auto& file : io::removeStaleTemporaries(out)) {
    spdlog::info("removed {}: a temporary file left by a run that was killed", file.string());
  }
  io::writeTextAtomic(out / "report.json", baseReport(s, "running").dump(2) + "\n");
}

void markRunIncomplete(const RunState& s, const std::string& status, nlohmann::json details) {
  nlohmann::json report = baseReport(s, status);
  report.update(details);
  try {
    io::writeTextAtomic(s.request.out / "report.json", report.dump(2) + "\n");
  } catch (const std::exception& e) {
    spdlog::warn("could not mark the run folder incomplete: {}", e.what());
  }
}

}  // namespace gvio::run
