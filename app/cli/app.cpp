#include "cli/app.hpp"

#include <glog/logging.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <system_error>

#include "cli/interrupt.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

void setupLogging(const CommonOptions& common) {
  auto logger = spdlog::stderr_color_mt("gvio");
  logger->set_pattern("%^[%l]%$ %v");
  spdlog::level::level_enum level = spdlog::level::info;
  if (common.verbose >= 2)
    level = spdlog::level::trace;
  else if (common.verbose == 1)
    level = spdlog::level::debug;
  if (common.quiet >= 2)
    level = spdlog::level::err;
  else if (common.quiet == 1)
    level = spdlog::level::warn;
  logger->set_level(level);
  spdlog::set_default_logger(logger);
  // Ceres reports through glog, whose warnings (e.g. a rank-deficient covariance, which the
  // smoother handles) would reach the terminal as multi-line noise before our one-line messages:
  // errors only, unless -v.
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = common.verbose >= 1 ? google::GLOG_INFO : google::GLOG_ERROR;
  if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("gvio");
}

bool userPathError(const std::error_code& ec) {
  return ec == std::errc::filename_too_long || ec == std::errc::not_a_directory ||
         ec == std::errc::too_many_symbolic_link_levels || ec == std::errc::permission_denied;
}

// Bad input is the user's to fix (exit 2, one line); anything else is our bug (exit 1).
int runGuarded(const std::function<int()>& run) {
  try {
    return run();
  } catch (const InvalidInput& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that the file system refuses outright (too long, a file where a
    // folder goes, a link loop, no permission) is theirs to fix, whichever query met it first.
    if (userPathError(e.code())) {
      spdlog::error("{}: {}", e.path1().string(), e.code().message());
      return 2;
    }
    spdlog::error("internal error: {}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return 1;
  }
}

// argv joined back into one line a shell would accept (report.json records how a run was made).
std::string commandLine(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    const bool plain = !arg.empty() && arg.find_first_not_of(
                                           "abcdefghijklmnopqrstuvwxyz"
                                           "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                           "0123456789_-+=./:,@%") == std::string::npos;
    if (!plain) {
      std::string quoted = "'";
      for (const char ch : arg) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
      arg = quoted + "'";
    }
    line += (i == 0 ? "" : " ") + arg;
  }
  return line;
}

}  // namespace

ProgressStyle CommonOptions::progressStyle() const {
  return chooseProgressStyle(!no_progress && quiet == 0, stderr);
}

void ConfigOptions::addTo(CLI::App& sub, const std::string& config_help,
                          const std::string& set_help) {
  sub.add_option("--config", file, config_help);
  sub.add_option("--set", overrides, set_help)->take_all()->allow_extra_args(false);
}

AppConfig ConfigOptions::load() const {
  ConfigSources sources;
  if (file) sources.file = *file;
  sources.overrides = overrides;
  return loadConfig(sources);
}

Cli buildCli(CommonOptions& common) {
  Cli cli;
  cli.app = std::make_unique<CLI::App>(
      "gvio: GNSS-assisted visual-inertial odometry, georeferenced maps and evaluation", "gvio");
  CLI::App& app = *cli.app;
  app.set_version_flag("--version", std::string(GVIO_VERSION));
  app.add_flag("-v,--verbose", common.verbose, "More log output (-vv: trace)");
  app.add_flag("-q,--quiet", common.quiet,
               "Warnings and errors only (-qq: errors only), no progress");
  app.add_flag("--no-progress", common.no_progress, "No progress bar or progress lines on stderr");
  app.fallthrough();
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success, 2 bad usage or bad input, 1 internal error, 130/143 interrupted "
      "(SIGINT/SIGTERM).");

  // Each subcommand is registered here only once it really works.
  std::vector<Command>& commands = cli.commands;
  commands.push_back(addInspectCommand(app, common));
  commands.push_back(addEvalCommand(app));
  commands.push_back(addRenderCommand(app, common));
  commands.push_back(addSimulateCommand(app, common));
  commands.push_back(addRunCommand(app, common));
  commands.push_back(addExportCommand(app));
  commands.push_back(addConsistencyCommand(app, common));
  commands.push_back(addFleetCommand(app));
  commands.push_back(addFleetTaskCommand(app));
  commands.push_back(addMergeCommand(app));
  commands.push_back(addViewCommand(app));
  return cli;
}

int runMain(int argc, char** argv) {
  CommonOptions common;
  common.command_line = commandLine(argc, argv);
  const Cli cli = buildCli(common);
  CLI::App& app = *cli.app;

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  setupLogging(common);
  ignoreFileSizeSignal();
  for (const auto& command : cli.commands) {
    if (command.app->parsed()) return runGuarded(command.run);
  }
  return 2;
}

}  // namespace gvio::cli
