#pragma once
// The fault matrix's drive and checks (tests/faults): a short simulated KITTI raw drive copied
// into a fresh folder per case, one fault injected into the copy, `gvio run` end to end, and what
// every case must show whatever its exit code: no crash, no temporary file left, no NaN or Inf in
// any output, and a folder's earlier files intact unless this run replaced them whole.
#include <sys/types.h>

#include <filesystem>
#include <map>
#include <string>

#include "support/fixtures.hpp"

namespace gvio::test {

// 10 s of the demo drive (101 stereo frames of 1241x376, 100 Hz oxts, 1 Hz SPP NMEA, truth),
// simulated once per build.
std::filesystem::path faultDrive();

// `gvio run` options of every case: the simulator's ENU origin and lever arm, so the fused
// trajectory is evaluated without alignment.
std::string runArgs(const std::filesystem::path& dataset, const std::filesystem::path& out);

class FaultCase {
 public:
  explicit FaultCase(const std::string& tag);  // copies the drive into a fresh folder
  [[nodiscard]] const std::filesystem::path& dataset() const { return dataset_; }
  [[nodiscard]] std::filesystem::path out() const { return dir_.path() / "run"; }
  [[nodiscard]] std::filesystem::path file(const std::string& relative) const {
    return dataset_ / relative;
  }
  CommandResult run(const std::string& extra = "") const;

 private:
  TempDir dir_;
  std::filesystem::path dataset_;
};

// The last line of stderr, which must be the error: "[error] " and one line.
std::string errorLine(const CommandResult& r);

// The checks every case ends with (gtest failures, not exceptions).
void expectNoTemporaries(const std::filesystem::path& out);
void expectFiniteOutputs(const std::filesystem::path& out);
std::string reportStatus(const std::filesystem::path& out);  // "" without report.json

// Every regular file of a folder and its bytes, to show later that nothing was lost or half
// written (the runs are deterministic, so a file rewritten whole has the same bytes).
using Snapshot = std::map<std::string, std::string>;
Snapshot snapshot(const std::filesystem::path& dir);
void expectIntact(const Snapshot& before, const std::filesystem::path& dir,
                  const std::string& except = "report.json");

// `gvio ARGS` started in the background with stderr to `err_file`.
class Background {
 public:
  Background(const std::string& args, const std::filesystem::path& err_file);
  ~Background();  // kills a child still running
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  [[nodiscard]] bool running();
  void signal(int sig) const;
  int wait();  // exit code, or 128 + the signal that ended it

 private:
  pid_t pid_ = -1;
  int status_ = -1;
};

}  // namespace gvio::test
