#include "fleet/child_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "odometry/error.hpp"

extern char** environ;  // NOLINT: POSIX's environment, handed to the children unchanged

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// posix_spawn's file actions, released on every path out.
class FileActions {
 public:
  FileActions() { posix_spawn_file_actions_init(&actions_); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions_); }
  FileActions(const FileActions&) = delete;
  FileActions& operator=(const FileActions&) = delete;
  posix_spawn_file_actions_t* get() { return &actions_; }

 private:
  posix_spawn_file_actions_t actions_{};
};

class SpawnAttributes {
 public:
  SpawnAttributes() { posix_spawnattr_init(&attributes_); }
  ~SpawnAttributes() { posix_spawnattr_destroy(&attributes_); }
  SpawnAttributes(const SpawnAttributes&) = delete;
  SpawnAttributes& operator=(const SpawnAttributes&) = delete;
  posix_spawnattr_t* get() { return &attributes_; }

 private:
  posix_spawnattr_t attributes_{};
};

}  // namespace

pid_t spawnLogged(const std::vector<std::string>& argv, const fs::path& log_file,
                  const std::optional<fs::path>& err_file, bool search_path) {
  if (argv.empty()) throw InvalidInput("spawnLogged: no program");
  FileActions actions;
  // No O_CLOEXEC: an open that lands on the target descriptor itself is not dup2'ed (which
  // would clear the flag), and the child would lose its stdout at exec.
  constexpr int kFlags = O_WRONLY | O_CREAT | O_APPEND;
  posix_spawn_file_actions_addopen(actions.get(), STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(actions.get(), STDOUT_FILENO, log_file.c_str(), kFlags, 0644);
  if (err_file) {
    posix_spawn_file_actions_addopen(actions.get(), STDERR_FILENO, err_file->c_str(), kFlags, 0644);
  } else {
    posix_spawn_file_actions_adddup2(actions.get(), STDOUT_FILENO, STDERR_FILENO);
  }
  SpawnAttributes attributes;
  posix_spawnattr_setflags(attributes.get(),
                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  posix_spawnattr_setpgroup(attributes.get(), 0);  // a group of its own
  sigset_t none, defaults;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(attributes.get(), &none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGXFSZ);
  posix_spawnattr_setsigdefault(attributes.get(), &defaults);

  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));  // NOLINT: POSIX API
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc =
      search_path
          ? posix_spawnp(&pid, args[0], actions.get(), attributes.get(), args.data(), environ)
          : posix_spawn(&pid, args[0], actions.get(), attributes.get(), args.data(), environ);
  if (rc != 0) {
    throw InvalidInput("cannot start '" + argv[0] + "': " + std::strerror(rc));
  }
  return pid;
}

std::optional<ChildExit> waitChild(pid_t pid) {
  int status = 0;
  rusage usage{};
  const pid_t done = ::wait4(pid, &status, 0, &usage);
  if (done <= 0) return std::nullopt;  // EINTR (a signal) or ECHILD
  ChildExit exit;
  exit.pid = done;
  if (WIFSIGNALED(status)) {
    exit.signal = WTERMSIG(status);
    exit.exit_code = 128 + exit.signal;
  } else {
    exit.exit_code = WEXITSTATUS(status);
  }
  exit.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
  return exit;
}

fs::path selfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the running executable: " + ec.message());
  return self;
}

std::string lastErrorLine(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  constexpr std::streamoff kTail = 64 * 1024;
  in.seekg(size > kTail ? size - kTail : 0);
  std::string line, last, last_error;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    if (line.starts_with("== gvio fleet")) continue;  // the fleet's own attempt header
    last = line;
    const auto tag = line.find("[error]");
    if (tag != std::string::npos) {
      std::string message = line.substr(tag + 7);
      while (!message.empty() && message.front() == ' ') message.erase(0, 1);
      last_error = message;
    }
  }
  return last_error.empty() ? last : last_error;
}

}  // namespace gvio::fleet
