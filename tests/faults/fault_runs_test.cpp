// The fault matrix, GNSS and output faults (docs/reliability.md): GNSS that lies, an output
// folder that cannot be written or fills up, and runs stopped by SIGINT, SIGTERM and SIGKILL.
// Whatever happens, files already in --out are never lost or half-written, no temporary file is
// left by a run that could clean up, and report.json says whether the run completed.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <chrono>
#include <csignal>
#include <nlohmann/json.hpp>
#include <thread>

#include "faults/fault_support.hpp"
#include "io/atomic_write.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

// NMEA 0183 checksum: XOR of the characters between '$' and '*'.
std::string withChecksum(const std::string& body) {
  unsigned char x = 0;
  for (const char ch : body) x ^= static_cast<unsigned char>(ch);
  return fmt::format("${}*{:02X}", body, x);
}

// Rewrites every sentence of an NMEA file with `edit` (fields split at ',', '$' and the checksum
// removed) and a fresh checksum.
template <typename Edit>
void editNmea(const fs::path& file, Edit edit) {
  std::istringstream in(readText(file));
  std::string out;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::istringstream fields(line.substr(1, line.find('*') - 1));
    for (std::string v; std::getline(fields, v, ',');) f.push_back(v);
    edit(f);
    std::string body;
    for (const auto& v : f) body += (body.empty() ? "" : ",") + v;
    out += withChecksum(body) + "\n";
  }
  writeText(file, out);
}

constexpr const char* kNmea = "gnss/fixes.nmea";

// An NMEA time field (hhmmss.ss) moved by whole seconds.
std::string shiftedTime(const std::string& hhmmss, int seconds) {
  const int t = std::stoi(hhmmss.substr(0, 2)) * 3600 + std::stoi(hhmmss.substr(2, 2)) * 60 +
                std::stoi(hhmmss.substr(4, 2)) + seconds;
  return fmt::format("{:02d}{:02d}{:02d}{}", t / 3600, t / 60 % 60, t % 60, hhmmss.substr(6));
}

// The sentences that carry the fix time: GGA, RMC and GST.
bool timed(const std::vector<std::string>& f) {
  return f[0] == "GPGGA" || f[0] == "GPRMC" || f[0] == "GPGST";
}

double fusedApe(const FaultCase& c) {
  const auto j = nlohmann::json::parse(readText(c.out() / "report.json"));
  return j["evaluation_fused"]["ape_none"]["rmse"].get<double>();
}

TEST(FaultGnss, KilometreOutlierBurstIsRejected) {
  FaultCase c("gnss_burst");
  // Fixes 5-7 (t = 4-6 s) jump 1 km north: 0.54 arc minutes of latitude.
  editNmea(c.file(kNmea), [](std::vector<std::string>& f) {
    if (f[0] == "GPGGA" && f[1] >= "125538" && f[1] < "125541") {
      f[2] = fmt::format("{:.7f}", std::stod(f[2]) + 0.54);
    }
  });
  const CommandResult r = c.run();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string fixes = readText(c.out() / "gnss_fixes.csv");
  std::size_t rejected = 0;
  for (std::size_t at = fixes.find("rejected"); at != std::string::npos;
       at = fixes.find("rejected", at + 1)) {
    ++rejected;
  }
  EXPECT_EQ(rejected, 3u) << fixes;
  const double ape = fusedApe(c);
  std::printf("1 km burst: %zu fixes rejected, fused APE %.2f m\n", rejected, ape);
  EXPECT_LT(ape, 2.5);
  expectFiniteOutputs(c.out());
}

TEST(FaultGnss, ForwardTimeJumpDropsTheFixesOutsideTheDrive) {
  FaultCase c("gnss_jump_forward");
  // From 12:55:39 on the receiver's clock is an hour ahead.
  editNmea(c.file(kNmea), [](std::vector<std::string>& f) {
    if (timed(f) && f[1] >= "125539") f[1] = shiftedTime(f[1], 3600);
  });
  const CommandResult r = c.run();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr(c.file(kNmea).string() + ": 6 skipped: 6 outside the drive"));
  EXPECT_EQ(reportStatus(c.out()), "complete");
  expectFiniteOutputs(c.out());
}

TEST(FaultGnss, BackwardTimeJumpIsRefused) {
  FaultCase c("gnss_jump_backward");
  // At 12:55:40 the clock steps back by 3 s: the log's time no longer increases, and which fixes
  // to trust is the user's call, so the reader names the line (as for image timestamps).
  editNmea(c.file(kNmea), [](std::vector<std::string>& f) {
    if (timed(f) && f[1] >= "125540") f[1] = shiftedTime(f[1], -3);
  });
  const CommandResult r = c.run();
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r), HasSubstr(c.file(kNmea).string() + ":19: timestamp not increasing"));
  EXPECT_FALSE(fs::exists(c.out()));
}

TEST(FaultGnss, NanFixIsRefused) {
  FaultCase c("gnss_nan");
  editNmea(c.file(kNmea), [](std::vector<std::string>& f) {
    if (f[0] == "GPGGA" && f[1] == "125538.00") f[2] = "nan";
  });
  const CommandResult r = c.run();
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r), HasSubstr(c.file(kNmea).string() + ":13: malformed GGA: latitude"));
  EXPECT_FALSE(fs::exists(c.out()));
}

TEST(FaultOutput, UnwritableOutputFolderIsRefusedBeforeAnyWork) {
  FaultCase c("unwritable");
  const fs::path blocker = c.dataset().parent_path() / "a_file";
  writeText(blocker, "not a folder\n");
  const CommandResult r = runGvio(runArgs(c.dataset(), blocker / "run"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r), HasSubstr((blocker / "run").string() + ": cannot create the output"));
  EXPECT_EQ(r.err.find("[info] vio"), std::string::npos) << "work began: " << r.err;
}

// A complete run of the drive in c.out(), as a user's earlier results.
Snapshot earlierRun(const FaultCase& c) {
  const CommandResult r = c.run();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return snapshot(c.out());
}

TEST(FaultOutput, FileSizeLimitWhileWritingTheMapKeepsTheEarlierFiles) {
  FaultCase c("file_size_limit");
  const Snapshot before = earlierRun(c);
  ASSERT_GT(before.at("map.pcd").size(), 2'048'000u) << "the map must exceed the limit below";
  // ulimit -f counts 1024-byte blocks: the trajectories fit, the map files do not (nor would
  // keyframes.bin, written before the map: left out here so that the map is the file that fails).
  const CommandResult r = runGvioWithEnv(
      "ulimit -f 2000;", runArgs(c.dataset(), c.out()) + " --set loops.save_keyframes=false");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r),
              HasSubstr((c.out() / "map.pcd").string() + ": write failed: File too large"));
  expectIntact(before, c.out());
  expectNoTemporaries(c.out());
  const auto report = nlohmann::json::parse(readText(c.out() / "report.json"));
  EXPECT_EQ(report["status"], "failed");
  EXPECT_EQ(report["stage"], "map");
}

// Waits until report.json says "running", then `wait` longer.
void waitUntilRunning(Background& run, const fs::path& out, std::chrono::milliseconds wait) {
  for (int i = 0; i < 3000 && run.running() && reportStatus(out) != "running"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(wait);
}

void expectInterrupted(int sig, const std::string& name) {
  FaultCase c("signal_" + name);
  const Snapshot before = earlierRun(c);
  const fs::path err = c.dataset().parent_path() / "stderr.txt";
  Background run(runArgs(c.dataset(), c.out()), err);
  waitUntilRunning(run, c.out(), std::chrono::milliseconds(500));  // well inside the VIO
  run.signal(sig);
  EXPECT_EQ(run.wait(), 128 + sig) << readText(err);
  const std::string text = readText(err);
  EXPECT_THAT(text, HasSubstr("[error] interrupted by " + name + " "));
  EXPECT_THAT(text, HasSubstr(" marks the run incomplete"));
  const auto report = nlohmann::json::parse(readText(c.out() / "report.json"));
  EXPECT_EQ(report["status"], "interrupted");
  EXPECT_EQ(report["signal"], name);
  expectIntact(before, c.out());
  expectNoTemporaries(c.out());
  expectFiniteOutputs(c.out());
}

TEST(FaultOutput, SigintStopsTheRunAndMarksItsFolder) {
  expectInterrupted(SIGINT, "SIGINT");
}
TEST(FaultOutput, SigtermStopsTheRunAndMarksItsFolder) {
  expectInterrupted(SIGTERM, "SIGTERM");
}

TEST(FaultOutput, SigkillWhileWritingTheMapLosesNothing) {
  FaultCase c("sigkill");
  const Snapshot before = earlierRun(c);
  const fs::path err = c.dataset().parent_path() / "stderr.txt";
  // Kill as soon as a map file's temporary appears (polled every millisecond); a few tries, since
  // the writes take tens of milliseconds.
  fs::path temporary;
  for (int attempt = 0; attempt < 5 && temporary.empty(); ++attempt) {
    Background run(runArgs(c.dataset(), c.out()), err);
    while (run.running() && temporary.empty()) {
      for (const auto& entry : fs::directory_iterator(c.out())) {
        const std::string name = entry.path().filename().string();
        if (io::isTemporaryName(entry.path()) && name.rfind(".map.", 0) == 0) {
          run.signal(SIGKILL);
          temporary = entry.path();
          break;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    run.wait();
  }
  ASSERT_FALSE(temporary.empty()) << "never saw a map file being written";
  expectIntact(before, c.out());  // the earlier map files, not the killed run's partial ones
  EXPECT_EQ(reportStatus(c.out()), "running");  // a dead PID: readers warn about the folder
  const CommandResult render =
      runGvio(fmt::format("render --run {} --view topdown --size 64x48 --out {}", quoted(c.out()),
                          quoted(c.dataset().parent_path() / "top.png")));
  EXPECT_THAT(render.err, HasSubstr("the run did not complete (status \"running\""));
  // The next run into the folder removes the dead run's temporary and completes.
  const CommandResult again = c.run();
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err, HasSubstr("removed " + temporary.string()));
  expectNoTemporaries(c.out());
  EXPECT_EQ(reportStatus(c.out()), "complete");
  expectIntact(before, c.out());  // deterministic: the same bytes again
}

}  // namespace
}  // namespace gvio::test
