#include "fleet/drive_task.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <fstream>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// The run's own accuracy where it had truth: the fused trajectory without alignment when GNSS
// was fused (what a map user gets), else the VIO's APE after SE(3) alignment (report.json, as
// `gvio run` wrote it).
void readApe(const nlohmann::json& report, DriveResult& r) {
  const auto rmse = [](const nlohmann::json& section, const char* metric) -> std::optional<double> {
    if (!section.is_object() || !section.contains(metric)) return std::nullopt;
    const auto& m = section[metric];
    if (!m.is_object() || !m.contains("rmse") || !m["rmse"].is_number()) return std::nullopt;
    return m["rmse"].get<double>();
  };
  if (const auto fused = rmse(report.value("evaluation_fused", nlohmann::json()), "ape_none")) {
    r.ape_m = fused;
    r.ape_metric = "evaluation_fused.ape_none";
  } else if (const auto vio = rmse(report.value("evaluation", nlohmann::json()), "ape_se3")) {
    r.ape_m = vio;
    r.ape_metric = "evaluation.ape_se3";
  }
}

std::optional<nlohmann::json> readReport(const fs::path& run_dir) {
  try {
    return io::readJsonObject(run_dir / "report.json");
  } catch (const InvalidInput&) {
    return std::nullopt;
  }
}

// What gvio run writes last of all (run/run_status.hpp): the folder holds a whole run ("partial":
// a finished run whose trajectory covers only part of its drive, run/coverage.hpp; running it
// again would give the same).
bool saysComplete(const std::optional<nlohmann::json>& report) {
  if (!report) return false;
  const std::string status = report->value("status", "");
  return status == "complete" || status == "partial";
}

}  // namespace

fs::path FleetPlan::runDir(std::size_t i) const {
  return out_dir / "runs" / drives.at(i).name;
}
fs::path FleetPlan::logFile(std::size_t i) const {
  return out_dir / "logs" / (drives.at(i).name + ".log");
}
fs::path FleetPlan::taskFile(std::size_t i) const {
  return out_dir / "tasks" / (drives.at(i).name + ".json");
}

std::vector<std::string> FleetPlan::runArgv(std::size_t i) const {
  const DriveSpec& d = drives.at(i);
  std::vector<std::string> argv{gvio.string(),     "--no-progress",    "run",
                                "--dataset",       d.dataset.string(), "--out",
                                runDir(i).string()};
  const bool own_threads =
      std::find(d.run_args.begin(), d.run_args.end(), "--threads") != d.run_args.end();
  if (threads_per_drive > 0 && !own_threads) {
    argv.insert(argv.end(), {"--threads", std::to_string(threads_per_drive)});
  }
  argv.insert(argv.end(), common_args.begin(), common_args.end());
  argv.insert(argv.end(), d.run_args.begin(), d.run_args.end());
  return argv;
}

nlohmann::json planToJson(const FleetPlan& plan) {
  nlohmann::json drives = nlohmann::json::array();
  for (const auto& d : plan.drives) {
    drives.push_back({{"line", d.line},
                      {"name", d.name},
                      {"dataset", d.dataset.string()},
                      {"run_args", d.run_args}});
  }
  return {{"out_dir", plan.out_dir.string()},
          {"gvio", plan.gvio.string()},
          {"common_args", plan.common_args},
          {"threads_per_drive", plan.threads_per_drive},
          {"drives", drives}};
}

FleetPlan planFromJson(const nlohmann::json& j, const fs::path& file) {
  try {
    FleetPlan plan;
    plan.out_dir = j.at("out_dir").get<std::string>();
    plan.gvio = j.at("gvio").get<std::string>();
    plan.common_args = j.at("common_args").get<std::vector<std::string>>();
    plan.threads_per_drive = j.at("threads_per_drive").get<int>();
    for (const auto& d : j.at("drives")) {
      DriveSpec spec;
      spec.line = d.at("line").get<std::size_t>();
      spec.name = d.at("name").get<std::string>();
      spec.dataset = d.at("dataset").get<std::string>();
      spec.run_args = d.at("run_args").get<std::vector<std::string>>();
      if (spec.name.empty() || spec.name == "." || spec.name == ".." ||
          spec.name.find('/') != std::string::npos) {
        throw InvalidInput("bad drive name '" + spec.name + "'");
      }
      plan.drives.push_back(std::move(spec));
    }
    return plan;
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError(file, 0, std::string("not a fleet plan: ") + e.what());
  } catch (const InvalidInput& e) {
    throw io::InputError(file, 0, std::string("not a fleet plan: ") + e.what());
  }
}

std::string stateName(DriveState state) {
  switch (state) {
    case DriveState::kComplete:
      return "complete";
    case DriveState::kFailed:
      return "failed";
    case DriveState::kInterrupted:
      return "interrupted";
    case DriveState::kNotRun:
      return "not_run";
  }
  return "not_run";
}

nlohmann::json resultToJson(const DriveResult& r) {
  nlohmann::json j{{"state", stateName(r.state)},  {"exit_code", r.exit_code},
                   {"attempts", r.attempts},       {"wall_s", r.wall_s},
                   {"peak_rss_mb", r.peak_rss_mb}, {"argv", r.argv}};
  j["ape_m"] = r.ape_m ? nlohmann::json(*r.ape_m) : nlohmann::json();
  if (!r.ape_metric.empty()) j["ape_metric"] = r.ape_metric;
  if (!r.error.empty()) j["error"] = r.error;
  return j;
}

DriveResult resultFromJson(const nlohmann::json& j) {
  DriveResult r;
  const std::string state = j.at("state").get<std::string>();
  for (const auto s : {DriveState::kComplete, DriveState::kFailed, DriveState::kInterrupted,
                       DriveState::kNotRun}) {
    if (stateName(s) == state) r.state = s;
  }
  r.exit_code = j.at("exit_code").get<int>();
  r.attempts = j.at("attempts").get<int>();
  r.wall_s = j.at("wall_s").get<double>();
  r.peak_rss_mb = j.at("peak_rss_mb").get<double>();
  r.argv = j.at("argv").get<std::vector<std::string>>();
  if (j.contains("ape_m") && j["ape_m"].is_number()) r.ape_m = j["ape_m"].get<double>();
  r.ape_metric = j.value("ape_metric", "");
  r.error = j.value("error", "");
  return r;
}

DriveResult describeExit(const FleetPlan& plan, std::size_t i, const ChildExit& exit, double wall_s,
                         int interrupt_signal) {
  DriveResult r;
  r.exit_code = exit.exit_code;
  r.wall_s = wall_s;
  r.peak_rss_mb = exit.peak_rss_mb;
  r.argv = plan.runArgv(i);
  const auto report = readReport(plan.runDir(i));
  if (exit.exit_code == 0 && saysComplete(report)) {
    r.state = DriveState::kComplete;
    readApe(*report, r);
    return r;
  }
  const bool interrupted = interrupt_signal != 0 || exit.signal == SIGINT ||
                           exit.signal == SIGTERM || exit.exit_code == 128 + SIGINT ||
                           exit.exit_code == 128 + SIGTERM;
  r.state = interrupted ? DriveState::kInterrupted : DriveState::kFailed;
  r.error = lastErrorLine(plan.logFile(i));
  if (exit.signal != 0) {
    r.error =
        fmt::format("killed by signal {}{}{}", exit.signal, r.error.empty() ? "" : ": ", r.error);
  } else if (r.error.empty()) {
    r.error = fmt::format("exited with code {}", exit.exit_code);
  } else if (exit.exit_code == 0) {
    r.error = "exited 0 but report.json does not say complete";
  }
  return r;
}

std::optional<DriveResult> readTaskRecord(const FleetPlan& plan, std::size_t i) {
  try {
    return resultFromJson(io::readJsonObject(plan.taskFile(i)));
  } catch (const std::exception&) {
    return std::nullopt;  // none yet, or one a killed task left unreadable: run the drive
  }
}

void writeTaskRecord(const FleetPlan& plan, std::size_t i, const DriveResult& r) {
  fs::create_directories(plan.taskFile(i).parent_path());
  io::writeTextAtomic(plan.taskFile(i), resultToJson(r).dump(2) + "\n");
}

// A command without its --threads: a run's outputs do not depend on it (gvio run --threads), and
// it follows the fleet's --jobs, which a later fleet may choose differently.
std::vector<std::string> withoutThreads(std::vector<std::string> argv) {
  for (std::size_t k = 0; k + 1 < argv.size(); ++k) {
    if (argv[k] == "--threads") {
      argv.erase(argv.begin() + static_cast<std::ptrdiff_t>(k),
                 argv.begin() + static_cast<std::ptrdiff_t>(k) + 2);
      break;
    }
  }
  return argv;
}

bool alreadyComplete(const FleetPlan& plan, std::size_t i) {
  const auto record = readTaskRecord(plan, i);
  if (!record || record->state != DriveState::kComplete ||
      withoutThreads(record->argv) != withoutThreads(plan.runArgv(i))) {
    return false;
  }
  return saysComplete(readReport(plan.runDir(i)));
}

pid_t startDrive(const FleetPlan& plan, std::size_t i, int attempt) {
  fs::create_directories(plan.logFile(i).parent_path());
  fs::create_directories(plan.runDir(i).parent_path());
  std::ofstream(plan.logFile(i), std::ios::app)
      << fmt::format("== gvio fleet: drive {}, attempt {}\n", plan.drives[i].name, attempt);
  return spawnLogged(plan.runArgv(i), plan.logFile(i));
}

DriveResult runDriveHere(const FleetPlan& plan, std::size_t i, int attempt) {
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = startDrive(plan, i, attempt);
  std::optional<ChildExit> exit;
  while (!(exit = waitChild(pid))) {
    if (errno != EINTR) throw std::runtime_error("lost the drive's process");
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  DriveResult r = describeExit(plan, i, *exit, wall_s, 0);
  r.attempts = attempt;
  writeTaskRecord(plan, i, r);
  return r;
}

}  // namespace gvio::fleet
