#include "faults/fault_support.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <csignal>
#include <nlohmann/json.hpp>
#include <regex>

#include "io/atomic_write.hpp"
#include "io/run_dir.hpp"

extern char** environ;

namespace gvio::test {
namespace fs = std::filesystem;

fs::path faultDrive() {
  return cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 10 --seed 3", GVIO_SOURCE_DIR));
}

std::string runArgs(const fs::path& dataset, const fs::path& out) {
  return fmt::format("run --dataset {} --out {} --no-progress {}", quoted(dataset), quoted(out),
                     kSimGeo);
}

FaultCase::FaultCase(const std::string& tag)
    : dir_("fault_" + tag), dataset_(dir_.path() / "drive") {
  fs::copy(faultDrive(), dataset_, fs::copy_options::recursive);
}

CommandResult FaultCase::run(const std::string& extra) const {
  return runGvio(runArgs(dataset_, out()) + " " + extra);
}

std::string errorLine(const CommandResult& r) {
  std::string err = r.err;
  while (!err.empty() && err.back() == '\n') err.pop_back();
  const std::size_t start = err.rfind('\n');
  std::string line = start == std::string::npos ? err : err.substr(start + 1);
  EXPECT_EQ(line.rfind("[error] ", 0), 0u) << "stderr:\n" << r.err;
  return line;
}

void expectNoTemporaries(const fs::path& out) {
  if (!fs::is_directory(out)) return;
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_FALSE(io::isTemporaryName(entry.path())) << "left behind: " << entry.path();
  }
}

void expectFiniteOutputs(const fs::path& out) {
  if (!fs::is_directory(out)) return;
  // "nan"/"inf" as words (any case), as the C++ and Python formatters write them.
  const std::regex non_finite(R"((^|[^A-Za-z_])[-+]?(nan|inf|infinity)($|[^A-Za-z_]))",
                              std::regex::icase);
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".tum" || ext == ".csv" || ext == ".json") {
      const std::string text = readText(entry.path());
      std::smatch m;
      EXPECT_FALSE(std::regex_search(text, m, non_finite))
          << entry.path() << " holds '" << m.str() << "'";
    }
  }
  if (fs::exists(out / "map.pcd")) {
    const io::MapCloud cloud = io::readMapCloud(out / "map.pcd");
    ASSERT_FALSE(cloud.p_enu.empty());
    for (std::size_t i = 0; i < cloud.p_enu.size(); ++i) {
      ASSERT_TRUE(cloud.p_enu[i].allFinite()) << "map.pcd point " << i;
    }
  }
}

std::string reportStatus(const fs::path& out) {
  if (!fs::exists(out / "report.json")) return "";
  return nlohmann::json::parse(readText(out / "report.json")).value("status", "");
}

Snapshot snapshot(const fs::path& dir) {
  Snapshot s;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file()) s[entry.path().filename().string()] = readText(entry.path());
  }
  return s;
}

void expectIntact(const Snapshot& before, const fs::path& dir, const std::string& except) {
  for (const auto& [name, bytes] : before) {
    if (name == except) continue;
    ASSERT_TRUE(fs::exists(dir / name)) << name << " was lost";
    EXPECT_TRUE(readText(dir / name) == bytes) << name << " changed (half-written?)";
  }
}

Background::Background(const std::string& args, const fs::path& err_file) {
  const std::string command =
      fmt::format("exec {} {} > /dev/null 2> {} < /dev/null", GVIO_BINARY, args, quoted(err_file));
  const char* argv[] = {"/bin/sh", "-c", command.c_str(), nullptr};
  // exec: the shell becomes gvio, so the signals reach it.
  const int rc =
      ::posix_spawn(&pid_, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ);
  if (rc != 0) pid_ = -1;
  EXPECT_EQ(rc, 0) << "posix_spawn failed";
}

Background::~Background() {
  if (pid_ > 0 && status_ < 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
}

bool Background::running() {
  if (pid_ <= 0 || status_ >= 0) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    status_ = status;
    return false;
  }
  return true;
}

void Background::signal(int sig) const {
  if (pid_ > 0) ::kill(pid_, sig);
}

int Background::wait() {
  if (pid_ <= 0) return -1;
  if (status_ < 0) ::waitpid(pid_, &status_, 0);
  if (WIFEXITED(status_)) return WEXITSTATUS(status_);
  if (WIFSIGNALED(status_)) return 128 + WTERMSIG(status_);
  return -1;
}

}  // namespace gvio::test
