// Determinism of gvio run: the same command twice writes the same run folder bit for bit, and the
// threaded pipeline (decoding ahead, keyframe work and the occupancy beside the estimator) writes
// the same folder as --threads 1.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

std::set<std::string> filesIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

// report.json without what measures time or memory (those differ from run to run anyway).
nlohmann::json withoutTimings(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto& [key, value] : j.items()) {
      const bool timing = key.starts_with("ms") || key.find("_ms") != std::string::npos ||
                          key == "timing_ms" || key.ends_with("wall_s") || key == "peak_rss_mb" ||
                          key == "command_line" || key.ends_with("_mb");
      if (!timing) out[key] = withoutTimings(value);
    }
    return out;
  }
  if (j.is_array()) {
    for (auto& v : j) v = withoutTimings(v);
  }
  return j;
}

TEST(CliRunThreads, ThreadedRunWritesTheSameFilesAsOneThread) {
  // GNSS fusion, loop closure and the dense map all on: every stage the threads touch.
  const fs::path drive = cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9", GVIO_SOURCE_DIR));
  TempDir tmp("cli_run_threads");
  for (const int threads : {1, 3}) {
    const CommandResult r = runGvio(
        fmt::format("run --dataset {} --out {} --no-progress --gnss graph --threads {} {}",
                    quoted(drive), quoted(tmp.path() / std::to_string(threads)), threads, kSimGeo));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const fs::path one = tmp.path() / "1", three = tmp.path() / "3";
  const std::set<std::string> files = filesIn(one);
  EXPECT_EQ(files, filesIn(three));
  for (const char* expected :
       {"trajectory_vio.tum", "trajectory.tum", "map.pcd", "map.bt", "map.ot", "loops.csv"}) {
    EXPECT_TRUE(files.count(expected)) << expected;
  }
  for (const std::string& name : files) {
    if (name == "report.json" || name == "config.yaml") continue;
    EXPECT_EQ(readText(one / name), readText(three / name)) << name << " differs";
  }
  const auto report = [](const fs::path& dir) {
    return withoutTimings(nlohmann::json::parse(readText(dir / "report.json")));
  };
  EXPECT_EQ(report(one), report(three));
  const auto map = nlohmann::json::parse(readText(one / "report.json"))["map"];
  EXPECT_GT(map["dense_points"].get<double>(), 0.0);
  // --threads is a run option, not configuration: config.yaml is the same.
  EXPECT_EQ(readText(one / "config.yaml"), readText(three / "config.yaml"));
}

// The determinism check: one command run twice (degraded GNSS with a seed, loops, the map),
// every file the same byte for byte, report.json the same but for what measures time.
TEST(CliRunDeterminism, TheSameCommandTwiceWritesTheSameBytes) {
  const fs::path drive = cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 7", GVIO_SOURCE_DIR));
  TempDir tmp("cli_run_twice");
  for (const char* name : {"a", "b"}) {
    const CommandResult r =
        runGvio(fmt::format("run --dataset {} --out {} --no-progress --gnss-noise spp --seed 11 {}",
                            quoted(drive), quoted(tmp.path() / name), kSimGeo));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const fs::path a = tmp.path() / "a", b = tmp.path() / "b";
  const std::set<std::string> files = filesIn(a);
  EXPECT_EQ(files, filesIn(b));
  EXPECT_TRUE(files.count("map.pcd") && files.count("trajectory.tum"));
  for (const std::string& name : files) {
    if (name == "report.json") continue;
    EXPECT_TRUE(readText(a / name) == readText(b / name)) << name << " differs";
  }
  const auto report = [](const fs::path& dir) {
    return withoutTimings(nlohmann::json::parse(readText(dir / "report.json")));
  };
  EXPECT_EQ(report(a), report(b));
}

TEST(CliRunThreads, RejectsZeroThreads) {
  const CommandResult r = runGvio("run --dataset /nonexistent --threads 0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gvio::test
