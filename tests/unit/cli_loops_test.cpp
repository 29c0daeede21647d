// gvio run's loop closure end to end (issue 15) on a simulated city block driven 1.3 times (a
// rounded 80 x 50 m rectangle at 8 m/s, SPP-grade GNSS): loops are found and verified in every
// GNSS mode and VIO mode, the loop-closed trajectory beats the open one and keeps the two passes
// together; a drive without a revisit closes none; a bad loop setting is a one-line error.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>

#include "fusion/vio_enu_alignment.hpp"
#include "io/loops_csv.hpp"
#include "io/trajectory_io.hpp"
#include "support/block_drive.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

class CliLoops : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<TempDir>("cli_loops");
    sim_ = simulatedBlockDrive("block_drive.tum");
  }
  static void TearDownTestSuite() { tmp_.reset(); }

  static fs::path runDir(const std::string& name) { return tmp_->path() / name; }
  // Without the map unless `map` (the map stage is the slowest part of a run).
  static nlohmann::json run(const std::string& name, const std::string& options, bool map = false) {
    const CommandResult r =
        runGvio(fmt::format("run --dataset {} --out {} --no-progress {} {}", quoted(sim_),
                            quoted(runDir(name)), map ? "" : "--set map.enabled=false", options));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(readText(runDir(name) / "report.json"));
  }
  // RMS over the accepted loops of the error of the pair's relative position in `estimate`
  // against the truth: how well the two passes of the final trajectory lie on each other.
  static double loopPairError(const std::string& name, const Trajectory& estimate) {
    const Trajectory truth = io::readTum(sim_ / "groundtruth.tum");
    double sum = 0.0;
    int n = 0;
    for (const io::LoopCsvRow& row : io::readLoopsCsv(runDir(name) / "loops.csv")) {
      if (!row.accepted) continue;
      const auto a = fusion::interpolatePose(estimate, row.candidate_t_ns);
      const auto b = fusion::interpolatePose(estimate, row.query_t_ns);
      const auto ta = fusion::interpolatePose(truth, row.candidate_t_ns);
      const auto tb = fusion::interpolatePose(truth, row.query_t_ns);
      if (!a || !b || !ta || !tb) continue;
      const Eigen::Vector3d est = b->translation() - a->translation();
      const Eigen::Vector3d ref = tb->translation() - ta->translation();
      sum += (est - ref).squaredNorm();
      ++n;
    }
    EXPECT_GT(n, 0);
    return n > 0 ? std::sqrt(sum / n) : std::numeric_limits<double>::infinity();
  }

  static std::unique_ptr<TempDir> tmp_;
  static fs::path sim_;
};
std::unique_ptr<TempDir> CliLoops::tmp_;
fs::path CliLoops::sim_;

TEST_F(CliLoops, PureVioClosesTheLoopsAndBeatsTheOpenTrajectory) {
  const nlohmann::json r = run("off", "--gnss off");
  const nlohmann::json& loops = r["loops"];
  ASSERT_TRUE(loops.is_object()) << r.dump(2);
  EXPECT_EQ(loops["frame"], "vio_world");
  EXPECT_GE(loops["accepted"].get<int>(), 20) << loops.dump(2);
  EXPECT_TRUE(loops["graph"]["converged"].get<bool>());
  EXPECT_EQ(loops["graph"]["active_loops"], loops["accepted"]);
  EXPECT_EQ(io::readLoopsCsv(runDir("off") / "loops.csv").size(),
            loops["verified"].get<std::size_t>());
  const double open = r["evaluation"]["ape_se3"]["rmse"].get<double>();
  const double closed = r["evaluation_loop_closed"]["ape_se3"]["rmse"].get<double>();
  const Trajectory final_trajectory = io::readTum(runDir("off") / "trajectory.tum");
  const double pair_error = loopPairError("off", final_trajectory);
  const double pair_error_vio =
      loopPairError("off", io::readTum(runDir("off") / "trajectory_vio.tum"));
  std::cout << fmt::format(
      "pure VIO: {} loops accepted of {} verified; APE (SE3) {:.3f} m open, {:.3f} m loop-closed; "
      "loop pairs {:.3f} m open, {:.3f} m closed; detection {:.2f} ms/keyframe, features {:.2f}\n",
      loops["accepted"].get<int>(), loops["verified"].get<int>(), open, closed, pair_error_vio,
      pair_error, loops["ms_detection_per_keyframe"]["mean"].get<double>(),
      loops["ms_features_per_keyframe"]["mean"].get<double>());
  EXPECT_LT(closed, 0.7 * open);
  EXPECT_LT(pair_error, 0.05);
  EXPECT_LT(pair_error, 0.5 * pair_error_vio);
}

TEST_F(CliLoops, WithSppGnssLoopsImproveTheFusedTrajectoryInEveryGnssMode) {
  const nlohmann::json without =
      run("graph_noloops", fmt::format("--gnss graph {} --set loops.enabled=false", kSimGeo), true);
  EXPECT_FALSE(without.contains("loops"));
  ASSERT_TRUE(without.contains("map"));
  EXPECT_FALSE(fs::exists(runDir("graph_noloops") / "loops.csv"));
  const double ape_without = without["evaluation_fused"]["ape_none"]["rmse"].get<double>();
  for (const char* mode : {"graph", "kf"}) {
    const bool map = std::string(mode) == "graph";
    const nlohmann::json r = run(mode, fmt::format("--gnss {} {}", mode, kSimGeo), map);
    const nlohmann::json& loops = r["loops"];
    EXPECT_EQ(loops["frame"], "enu");
    if (map) {
      // The map at the revisit (found by the run itself): the second pass lies on the first.
      const nlohmann::json& with_map = r["map"]["revisits"];
      const nlohmann::json& without_map = without["map"]["revisits"];
      std::cout << fmt::format(
          "map at revisits: {:.1f} % of the second pass within 0.2 m with loops, {:.1f} % "
          "without\n",
          100.0 * with_map["fraction_within"].get<double>(),
          100.0 * without_map["fraction_within"].get<double>());
      EXPECT_GT(with_map["second_pass_keyframes"].get<int>(), 50);
      EXPECT_GE(with_map["fraction_within"].get<double>(), 0.95);
      EXPECT_TRUE(with_map["meets_target"].get<bool>());
      // Without loops the second pass lies where its own SPP fixes put it. Measured on this drive:
      // 94.1 % with the VIO of 2026-11-27 (its full-resolution KLT pass; 36.9 % when this test was
      // written) and 97.4 % with loops: the loops must still add to it.
      EXPECT_GT(with_map["fraction_within"].get<double>(),
                without_map["fraction_within"].get<double>());
    }
    EXPECT_GE(loops["accepted"].get<int>(), 20) << mode;
    EXPECT_GT(loops["graph"]["fixes"].get<int>(), 40) << mode;
    const double ape = r["evaluation_fused"]["ape_none"]["rmse"].get<double>();
    const double pair_error = loopPairError(mode, io::readTum(runDir(mode) / "trajectory.tum"));
    const double pair_error_without =
        loopPairError(mode, io::readTum(runDir("graph_noloops") / "trajectory.tum"));
    std::cout << fmt::format(
        "{}: fused APE {:.3f} m with loops, {:.3f} m without (graph); loop pairs {:.3f} m with, "
        "{:.3f} m without\n",
        mode, ape, ape_without, pair_error, pair_error_without);
    EXPECT_LT(ape, ape_without) << mode;
    EXPECT_LT(pair_error, 0.05) << mode;
    EXPECT_LT(pair_error, 0.25 * pair_error_without) << mode;
    EXPECT_TRUE(fs::exists(runDir(mode) / "trajectory_lla.csv"));
    // The causal output (the paper's filter in kf mode) stays beside the loop-closed one.
    EXPECT_TRUE(fs::exists(runDir(mode) / "trajectory_online.tum"));
    EXPECT_EQ(r["gnss"]["smoothed"].get<bool>(), std::string(mode) == "graph");
    EXPECT_TRUE(r["loops"]["applied"].get<bool>());
  }
}

TEST_F(CliLoops, StereoOnlyAndMonoImuCloseLoopsToo) {
  for (const char* mode : {"stereo", "mono-imu"}) {
    const nlohmann::json r = run(mode, fmt::format("--gnss off --set vio.mode={}", mode));
    const nlohmann::json& loops = r["loops"];
    std::cout << fmt::format(
        "{}: {} loops accepted of {} verified, APE (SE3) {:.3f} m open, {:.3f} "
        "m loop-closed\n",
        mode, loops["accepted"].get<int>(), loops["verified"].get<int>(),
        r["evaluation"]["ape_se3"]["rmse"].get<double>(),
        r["evaluation_loop_closed"]["ape_se3"]["rmse"].get<double>());
    EXPECT_GE(loops["accepted"].get<int>(), 10) << mode;
    EXPECT_LE(r["evaluation_loop_closed"]["ape_se3"]["rmse"].get<double>(),
              r["evaluation"]["ape_se3"]["rmse"].get<double>())
        << mode;
  }
}

TEST(CliLoopsNoRevisit, ADriveThatNeverComesBackClosesNoLoop) {
  // 20 s of the demo drive (no revisit), candidates allowed from 10 s back within 100 m: they
  // are searched and verified, and none is a loop.
  const fs::path sim = cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9 --gnss-noise rtk",
                  GVIO_SOURCE_DIR));
  TempDir tmp("cli_loops_none");
  const CommandResult r = runGvio(fmt::format(
      "run --dataset {} --out {} --no-progress --gnss off --set map.enabled=false --set "
      "loops.min_separation_s=10 --set loops.search_radius_m=100",
      quoted(sim), quoted(tmp.path() / "run")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(readText(tmp.path() / "run" / "report.json"));
  EXPECT_GT(report["loops"]["pairs_in_radius"].get<int>(), 0);
  EXPECT_EQ(report["loops"]["accepted"].get<int>(), 0) << report["loops"].dump(2);
}

TEST(CliLoopsConfig, BrokenOrEmptyLoopValuesExitTwoWithOneLine) {
  for (const char* bad : {"loops.min_inliers=x", "loops.ratio=2", "loops.max_heading_deg=0",
                          "loops.search_radius_m=", "loops.graph_chi2=-1", "loops.enabled=maybe"}) {
    const CommandResult r =
        runGvio(fmt::format("run --dataset /nonexistent --no-progress --set {}", bad));
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("loops."), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace gvio::test
