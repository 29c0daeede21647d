#include "fuzz/harness.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <system_error>

#include "fuzz/targets_list.hpp"
#include "odometry/error.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {

namespace fs = std::filesystem;

namespace {

// The per-process root of the targets' folders, removed when the process exits normally (a
// crashing fuzzer leaves it for the post-mortem).
class Workspaces {
 public:
  Workspaces() : root_(fs::temp_directory_path() / ("gvio-fuzz-" + std::to_string(::getpid()))) {}
  ~Workspaces() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  Workspaces(const Workspaces&) = delete;
  Workspaces& operator=(const Workspaces&) = delete;

  const fs::path& folderOf(const Target& target) {
    auto it = prepared_.find(target.name);
    if (it != prepared_.end()) return it->second;
    const fs::path dir = root_ / target.name;
    fs::create_directories(dir);
    target.prepare(dir);
    return prepared_.emplace(target.name, dir).first->second;
  }

 private:
  fs::path root_;
  std::map<std::string, fs::path> prepared_;
};

Workspaces& workspaces() {
  static Workspaces instance;  // test-harness state only: the libraries keep none
  return instance;
}

void writeBytes(const fs::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + file.string());
}

// A refusal must be one line that names the file it is about.
Outcome judgeRefusal(const Target& target, const std::string& message) {
  const std::string name =
      target.names.empty() ? fs::path(target.file).filename().string() : target.names;
  if (message.find('\n') != std::string::npos)
    return {Verdict::kBug, "the error spans several lines: " + message};
  if (name != "-" && message.find(name) == std::string::npos)
    return {Verdict::kBug, "the error does not name " + name + ": " + message};
  return {Verdict::kRejected, message};
}

}  // namespace

void require(bool ok, const std::string& what) {
  if (!ok) throw InvariantViolation(what);
}

const std::vector<Target>& targets() {
  static const std::vector<Target> all = [] {
    std::vector<Target> list;
    addTextTargets(list);
    addFileTargets(list);
    addFleetTargets(list);
    addRos2Targets(list);
    return list;
  }();
  return all;
}

const Target* findTarget(std::string_view name) {
  for (const Target& t : targets())
    if (t.name == name) return &t;
  return nullptr;
}

fs::path workspace(const Target& target) {
  return workspaces().folderOf(target);
}

Outcome runInput(const Target& target, std::string_view input) {
  const fs::path dir = workspace(target);
  writeBytes(dir / target.file, input);
  try {
    target.read(dir);
    return {Verdict::kAccepted, ""};
  } catch (const InvalidInput& e) {
    return judgeRefusal(target, e.what());
  } catch (const InvariantViolation& e) {
    return {Verdict::kBug, std::string("accepted but wrong: ") + e.what()};
  } catch (const std::exception& e) {
    return {Verdict::kBug, std::string("escaped as an internal error: ") + e.what()};
  }
}

std::string seedOf(const Target& target) {
  const fs::path dir = workspace(target);
  target.prepare(dir);  // the fuzzed file may hold an earlier input
  return test::readText(dir / target.file);
}

std::string toString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAccepted:
      return "accepted";
    case Verdict::kRejected:
      return "rejected";
    case Verdict::kBug:
      return "bug";
  }
  return "?";
}

}  // namespace gvio::fuzz
