#pragma once
// Child processes of `gvio fleet`: started with posix_spawn (stdin from /dev/null, stdout and
// stderr appended to a log file, in a process group of their own so that the terminal's Ctrl-C
// reaches the fleet alone, which passes it on once), reaped with wait4 for their exit status and
// peak resident memory.
#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace gvio::fleet {

struct ChildExit {
  pid_t pid = 0;
  int exit_code = 0;  // the exit status, or 128 + the signal that ended the process (as shells)
  int signal = 0;     // the signal that ended it, 0 when it exited
  double peak_rss_mb = 0.0;  // wait4's ru_maxrss: the process's own peak, not its children's
};

// Starts `argv` (argv[0] a path, or a name looked up in PATH when `search_path`), its output to
// `log_file` (appended; created if missing) and, when given, its standard error to `err_file`.
// Throws InvalidInput naming the program when it cannot be started.
pid_t spawnLogged(const std::vector<std::string>& argv, const std::filesystem::path& log_file,
                  const std::optional<std::filesystem::path>& err_file = std::nullopt,
                  bool search_path = false);

// Blocks until the child `pid` (or, for -1, any child) ends. Returns nullopt when the wait was
// interrupted by a signal (the caller checks what arrived) or there is no child to wait for.
std::optional<ChildExit> waitChild(pid_t pid = -1);

// The running executable (/proc/self/exe), so that the fleet's children run this same gvio.
std::filesystem::path selfExecutable();

// The last line of `file` that holds "[error]" (without everything up to and including that
// tag), else its last non-empty line that is not the fleet's attempt header; "" for an empty or
// missing file. Reads at most the last 64 KiB.
std::string lastErrorLine(const std::filesystem::path& file);

}  // namespace gvio::fleet
