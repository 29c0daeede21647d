#pragma once
// The gvio command line: global flags, subcommand registration, exit codes
// (0 ok, 2 bad usage or bad input, 1 internal error).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/config.hpp"
#include "cli/progress.hpp"

namespace gvio::cli {

struct CommonOptions {
  int verbose = 0;
  int quiet = 0;
  bool no_progress = false;
  std::string command_line;  // the whole invocation, shell-quoted where needed (for reports)

  [[nodiscard]] ProgressStyle progressStyle() const;
};

// Checks an unsigned option's text: a whole number >= 0. CLI11 would convert "-1" into an
// unsigned option by wrapping it into a huge count (or seed); this refuses it in one line instead.
inline CLI::Validator countValidator(const std::string& name = "COUNT") {
  return CLI::Validator(
      [](std::string& text) {
        const bool digits =
            !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
        return digits ? std::string() : "'" + text + "' is not a whole number >= 0";
      },
      name);
}

// --config FILE and --set key=value, on the subcommands that take configuration.
struct ConfigOptions {
  std::optional<std::string> file;
  std::vector<std::string> overrides;

  // --config and --set; a command that reads only some keys says which in the help texts.
  void addTo(CLI::App& sub,
             const std::string& config_help = "YAML configuration (see assets/config/default.yaml)",
             const std::string& set_help =
                 "Override one config key: --set dataset.gap_factor=3 (repeatable)");
  [[nodiscard]] AppConfig load() const;
};

struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command addInspectCommand(CLI::App& app, const CommonOptions& common);
Command addEvalCommand(CLI::App& app);
Command addRenderCommand(CLI::App& app, const CommonOptions& common);
Command addSimulateCommand(CLI::App& app, const CommonOptions& common);
Command addRunCommand(CLI::App& app, const CommonOptions& common);
Command addExportCommand(CLI::App& app);
Command addConsistencyCommand(CLI::App& app, const CommonOptions& common);
Command addFleetCommand(CLI::App& app);
Command addFleetTaskCommand(CLI::App& app);
Command addMergeCommand(CLI::App& app);
Command addViewCommand(CLI::App& app);

// The whole command line, every subcommand registered, not yet parsed: runMain parses it, and the
// CLI reference (docs/reference/cli.md, tests/unit/docs_reference_test.cpp) lists its subcommands
// from it rather than from a copy that could go stale. The commands refer to `common`, which must
// outlive them.
struct Cli {
  std::unique_ptr<CLI::App> app;  // CLI::App can be neither copied nor moved
  std::vector<Command> commands;
};
Cli buildCli(CommonOptions& common);

int runMain(int argc, char** argv);

}  // namespace gvio::cli
