// `gvio run`: the sensor-set choice, bad input as one line with exit 2, an unreadable image that
// only skips its frame, and an end-to-end run on a simulated drive (trajectory, report.json,
// config.yaml, evaluation against the simulator's truth).
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/config.hpp"
#include "io/dataset.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"
#include "run/stats.hpp"
#include "run/vio_runner.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using odometry::VioMode;
using testing::HasSubstr;

CommandResult runOn(const fs::path& dataset, const fs::path& out, const std::string& extra = "") {
  return runGvio(fmt::format("run --dataset {} --out {} --no-progress {}", quoted(dataset),
                             quoted(out), extra));
}

// Exit code 2 and exactly one stderr line, an "[error]" containing `needle`.
::testing::AssertionResult failsOnOneLine(const CommandResult& r, const std::string& needle) {
  if (r.exit_code != 2) {
    return ::testing::AssertionFailure() << "exit code " << r.exit_code << ", stderr: " << r.err;
  }
  if (std::count(r.err.begin(), r.err.end(), '\n') != 1 || !r.err.ends_with('\n')) {
    return ::testing::AssertionFailure() << "stderr is not one line: '" << r.err << "'";
  }
  if (r.err.find("[error]") == std::string::npos || r.err.find(needle) == std::string::npos) {
    return ::testing::AssertionFailure() << "stderr '" << r.err << "' lacks [error] or " << needle;
  }
  return ::testing::AssertionSuccess();
}

// A dataset with `cameras` cameras, a few frames and an IMU at `imu_hz` (0: none), for the mode
// choice alone.
io::Dataset sensors(std::size_t cameras, double imu_hz) {
  io::Dataset ds;
  ds.root = "/data/drive";
  ds.cameras.resize(cameras);
  ds.frames.resize(3);
  for (int i = 0; imu_hz > 0.0 && i < 20; ++i) {
    ImuSample s;
    s.t_ns = static_cast<std::int64_t>(std::llround(i * 1e9 / imu_hz));
    ds.imu.push_back(s);
  }
  return ds;
}

std::string modeError(const std::string& mode, const io::Dataset& ds) {
  try {
    run::chooseVioMode(mode, ds);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

TEST(CliRunMode, AutoPicksFromTheSensors) {
  EXPECT_EQ(run::chooseVioMode("auto", sensors(2, 100.0)), VioMode::kStereoImu);
  EXPECT_EQ(run::chooseVioMode("auto", sensors(2, 10.0)), VioMode::kStereo);  // KITTI sync
  EXPECT_EQ(run::chooseVioMode("auto", sensors(2, 0.0)), VioMode::kStereo);
  EXPECT_EQ(run::chooseVioMode("auto", sensors(1, 200.0)), VioMode::kMonoImu);
  EXPECT_THAT(modeError("auto", sensors(1, 10.0)), HasSubstr("no VIO mode fits"));
  EXPECT_THAT(modeError("auto", sensors(0, 100.0)), HasSubstr("no camera frames"));
}

TEST(CliRunMode, ExplicitModeNeedsItsSensors) {
  EXPECT_EQ(run::chooseVioMode("mono-imu", sensors(2, 100.0)), VioMode::kMonoImu);
  EXPECT_EQ(run::chooseVioMode("stereo", sensors(2, 100.0)), VioMode::kStereo);
  EXPECT_THAT(modeError("stereo", sensors(1, 100.0)), HasSubstr("needs two cameras"));
  EXPECT_THAT(modeError("stereo-imu", sensors(2, 10.0)), HasSubstr("needs an IMU of >= 50 Hz"));
  EXPECT_THAT(modeError("stereo-imu", sensors(2, 10.0)), HasSubstr("/data/drive"));
}

TEST(CliRunStats, MeanP95Max) {
  std::vector<double> ms;
  for (int i = 100; i >= 1; --i) ms.push_back(i);
  const run::TimingSummary s = run::summarizeTimings(ms);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.p95, 95.0);
  EXPECT_DOUBLE_EQ(s.max, 100.0);
  EXPECT_DOUBLE_EQ(run::summarizeTimings({}).max, 0.0);
  EXPECT_DOUBLE_EQ(run::summarizeTimings({3.0}).p95, 3.0);
  EXPECT_GT(run::peakRssMb(), 1.0);
}

TEST(CliRunConfig, VioKeysLoadAndValidate) {
  const cli::AppConfig c = cli::loadConfig(
      {std::nullopt, {"vio.mode=stereo", "vio.window_size=7", "vio.tracker.max_features=150"}});
  EXPECT_EQ(c.vio.mode, "stereo");
  EXPECT_EQ(c.vio.estimator.window_size, 7);
  EXPECT_EQ(c.vio.estimator.tracker.max_features, 150);
  const auto error = [](const std::string& set) {
    try {
      cli::loadConfig({std::nullopt, {set}});
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error("vio.mode=fast"), HasSubstr("vio.mode"));
  EXPECT_THAT(error("vio.window_size=1"), HasSubstr("vio.window_size"));
  EXPECT_THAT(error("vio.tracker.klt_window_px=4"), HasSubstr("vio.tracker.klt_window_px"));
}

class CliRunBadInput : public ::testing::Test {
 protected:
  void SetUp() override { drive_ = writeKittiFixture(tmp_.path(), KittiFixture{}); }
  TempDir tmp_{"cli_run"};
  fs::path drive_;
};

TEST_F(CliRunBadInput, MissingDataset) {
  const fs::path missing = tmp_.path() / "no_such_drive";
  EXPECT_TRUE(failsOnOneLine(runOn(missing, tmp_.path() / "out"), "no_such_drive"));
  EXPECT_FALSE(fs::exists(tmp_.path() / "out"));
}

TEST_F(CliRunBadInput, BadGnssValue) {
  EXPECT_TRUE(failsOnOneLine(runOn(drive_, tmp_.path() / "out", "--gnss gps"), "--gnss 'gps'"));
  EXPECT_TRUE(
      failsOnOneLine(runOn(drive_, tmp_.path() / "out", "--gnss graph --set fusion.origin=91,0,0"),
                     "fusion.origin"));
}

TEST_F(CliRunBadInput, BadVioMode) {
  EXPECT_TRUE(failsOnOneLine(runOn(drive_, tmp_.path() / "out", "--set vio.mode=fast"),
                             "vio.mode must be one of"));
}

TEST_F(CliRunBadInput, ModeTheDatasetCannotServe) {
  // A sync-style drive (10 Hz oxts) has no usable IMU.
  KittiFixture sync;
  sync.drive_name = "2011_09_26_drive_0002_sync";
  sync.oxts_rate_hz = 10;
  const fs::path drive = writeKittiFixture(tmp_.path(), sync);
  const CommandResult r = runOn(drive, tmp_.path() / "out", "--set vio.mode=stereo-imu");
  EXPECT_EQ(r.exit_code, 2);
  // The reader's own warning about the slow oxts comes first, then the one error line.
  EXPECT_THAT(r.err, HasSubstr("too slow for IMU preintegration"));
  const std::string last = r.err.substr(r.err.rfind('\n', r.err.size() - 2) + 1);
  EXPECT_THAT(last, HasSubstr("[error]"));
  EXPECT_THAT(last, HasSubstr("needs an IMU of >= 50 Hz"));
  EXPECT_EQ(r.err.find("[error]"), r.err.rfind("[error]"));
}

TEST_F(CliRunBadInput, MonoDatasetWithStereoMode) {
  const fs::path mono = cachedSimulation(fmt::format(
      "--trajectory {}/assets/demo/drive.tum --seconds 1 --camera mono --seed 3", GVIO_SOURCE_DIR));
  EXPECT_TRUE(failsOnOneLine(runOn(mono, tmp_.path() / "out", "--set vio.mode=stereo"),
                             "needs two cameras"));
}

// A damaged image skips its frame with a warning naming the file; the run goes on (exit 0).
TEST_F(CliRunBadInput, UnreadableImageSkipsItsFrame) {
  const fs::path image = drive_ / "image_01" / "data" / "0000000003.png";
  writeText(image, "not a png");
  const fs::path out = tmp_.path() / "out";
  const CommandResult r = runOn(drive_, out, "--gnss off");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("0000000003.png"));
  const auto report = nlohmann::json::parse(readText(out / "report.json"));
  EXPECT_EQ(report["counts"]["frames_skipped_unreadable"], 1);
  EXPECT_EQ(report["gnss"]["requested"], "off");
  EXPECT_TRUE(fs::exists(out / "trajectory_vio.tum"));
}

// Frames from the end of the default initialisation window on.
double framesAfterInit(const io::Dataset& ds) {
  const std::int64_t t0 = ds.frames.front().t_ns;
  const auto init_ns =
      static_cast<std::int64_t>(cli::AppConfig{}.vio.estimator.init_window_s * 1e9);
  return static_cast<double>(
      std::count_if(ds.frames.begin(), ds.frames.end(),
                    [&](const io::FrameRecord& f) { return f.t_ns - t0 >= init_ns; }));
}

// 8 s of the embedded demo drive (81 stereo frames, 100 Hz IMU, 1 Hz SPP GNSS, exact truth).
class CliRunEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim_ = cachedSimulation(
        fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 7", GVIO_SOURCE_DIR));
    dir_ = std::make_unique<TempDir>("cli_run_e2e");
    result_ = runGvio(fmt::format("run --dataset {} --out {} --no-progress", quoted(sim_),
                                  quoted(dir_->path() / "run")));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override { ASSERT_EQ(result_.exit_code, 0) << result_.err; }
  static fs::path run() { return dir_->path() / "run"; }
  static nlohmann::json report() { return nlohmann::json::parse(readText(run() / "report.json")); }

  static fs::path sim_;
  static std::unique_ptr<TempDir> dir_;
  static CommandResult result_;
};
fs::path CliRunEndToEnd::sim_;
std::unique_ptr<TempDir> CliRunEndToEnd::dir_;
CommandResult CliRunEndToEnd::result_;

TEST_F(CliRunEndToEnd, WritesAFiniteTrajectoryForMostFrames) {
  const io::Dataset ds = io::readDataset(sim_, std::nullopt, {});
  ASSERT_EQ(ds.frames.size(), 81u);
  const Trajectory traj = io::readTum(run() / "trajectory_vio.tum");
  ASSERT_FALSE(traj.empty());
  // Frames of the initialisation window have no pose yet; from its end on, >= 90 % must have one.
  const std::int64_t t0 = ds.frames.front().t_ns;
  const auto init_ns =
      static_cast<std::int64_t>(cli::AppConfig{}.vio.estimator.init_window_s * 1e9);
  EXPECT_LE(traj.t_ns.front() - t0, init_ns + 500'000'000) << "initialised late";
  EXPECT_GE(static_cast<double>(traj.size()), 0.9 * framesAfterInit(ds));
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_TRUE(traj.poses[i].matrix().allFinite()) << "pose " << i;
    EXPECT_TRUE(std::any_of(ds.frames.begin(), ds.frames.end(),
                            [&](const io::FrameRecord& f) { return f.t_ns == traj.t_ns[i]; }))
        << "stamp " << traj.t_ns[i] << " is no frame's";
  }
  EXPECT_EQ(firstNonIncreasingStamp(traj), -1);
  EXPECT_EQ(readText(run() / "trajectory_vio.tum").find("nan"), std::string::npos);
}

TEST_F(CliRunEndToEnd, ReportHasTheContractFields) {
  const auto r = report();
  EXPECT_EQ(r["gvio_version"], GVIO_VERSION);
  EXPECT_THAT(r["command_line"].get<std::string>(), HasSubstr("run --dataset"));
  EXPECT_EQ(r["dataset"]["format"], "kitti-raw");
  EXPECT_EQ(r["dataset"]["variant"], "extract");
  EXPECT_EQ(r["dataset"]["frames"], 81);
  EXPECT_EQ(r["dataset"]["imu_samples"], 801);
  EXPECT_EQ(r["dataset"]["gnss_fixes"], 9);
  EXPECT_EQ(r["mode"], "stereo-imu");
  // KITTI's layout states no IMU noise: imu.*, as configured.
  EXPECT_EQ(r["imu_noise_source"], "config");
  EXPECT_DOUBLE_EQ(r["imu_noise"].value("acc_noise_density", -1.0),
                   cli::AppConfig{}.imu.noise.acc_noise_density);
  EXPECT_DOUBLE_EQ(r["imu_noise"].value("gyr_random_walk", -1.0),
                   cli::AppConfig{}.imu.noise.gyr_random_walk);
  EXPECT_EQ(r["rectification"]["identity"], true);  // the simulator renders rectified cameras
  for (const char* key :
       {"frames", "keyframes", "initializations", "lost_frames", "coasted_frames", "imu_gaps",
        "exposure_corrected_frames", "stereo_gain_corrected_frames", "frames_skipped_unreadable"}) {
    EXPECT_TRUE(r["counts"].contains(key)) << key;
  }
  // The simulator's exposure is constant unless asked for (sim.exposure_change).
  EXPECT_EQ(r["counts"]["exposure_corrected_frames"], 0);
  EXPECT_EQ(r["counts"]["stereo_gain_corrected_frames"], 0);
  EXPECT_EQ(r["counts"]["frames"], 81);
  EXPECT_GE(r["counts"]["keyframes"].get<int>(), 1);
  EXPECT_GE(r["counts"]["initializations"].get<int>(), 1);
  EXPECT_EQ(r["counts"]["frames_skipped_unreadable"], 0);
  // The front end's per-frame means: a textured street keeps well over a hundred tracks, most of
  // them stereo-matched; what it rejects is a fraction of what it tracks.
  const nlohmann::json& t = r["tracker"];
  std::cout << "tracker: " << t.dump() << "\n";
  EXPECT_GT(t["tracked_per_frame"].get<double>(), 100.0);
  EXPECT_GT(t["stereo_matches_per_frame"].get<double>(),
            0.5 * t["tracked_per_frame"].get<double>());
  EXPECT_LE(t["stereo_matches_per_frame"].get<double>(),
            t["tracked_per_frame"].get<double>() + t["new_per_frame"].get<double>());
  EXPECT_LT(t["rejected_forward_backward_per_frame"].get<double>(),
            0.5 * t["tracked_per_frame"].get<double>());
  EXPECT_GE(t["rejected_ransac_per_frame"].get<double>(), 0.0);
  EXPECT_GE(t["rejected_stereo_per_frame"].get<double>(), 0.0);
  for (const char* stage : {"tracking", "estimator", "total"}) {
    for (const char* stat : {"mean", "p95", "max"}) {
      EXPECT_TRUE(r["timing_ms"][stage][stat].is_number()) << stage << "." << stat;
    }
  }
  EXPECT_GT(r["timing_ms"]["total"]["mean"].get<double>(), 0.0);
  EXPECT_GT(r["wall_s"].get<double>(), 0.0);
  // The whole command takes longer than its VIO stage, and each stage's time is there.
  EXPECT_GT(r.value("run_wall_s", -1.0), r["wall_s"].get<double>());
  const nlohmann::json stages = r.value("stage_wall_s", nlohmann::json::object());
  for (const char* stage : {"read", "vio", "gnss", "loops", "trajectories", "map"})
    EXPECT_GE(stages.value(stage, -1.0), 0.0) << stage;
  EXPECT_GT(r["peak_rss_mb"].get<double>(), 10.0);
  // --gnss auto with fixes in the dataset: the graph fusion.
  EXPECT_EQ(r["gnss"]["mode"], "graph");
  EXPECT_EQ(r["gnss"]["requested"], "auto");
  EXPECT_EQ(r["gnss"]["fixes"], 9);
  EXPECT_GE(r["gnss"]["used"].get<int>(), 5);
  EXPECT_EQ(r["gnss"]["registered"], true);
  EXPECT_TRUE(r["gnss"]["ms_per_fix"]["mean"].is_number());
  EXPECT_TRUE(r["outages"].is_array());
  // fusion.vio_* auto with stereo+IMU: the model measured for that mode.
  EXPECT_DOUBLE_EQ(r["vio_noise"].value("drift_fraction", -1.0), 0.002);
  EXPECT_DOUBLE_EQ(r["vio_noise"].value("sigma_floor_m", -1.0), 0.01);
  EXPECT_DOUBLE_EQ(r["vio_noise"].value("rot_floor_rad", -1.0), 2e-4);
  ASSERT_TRUE(r["events"].is_array());
  bool initialized = false;
  for (const auto& e : r["events"]) {
    EXPECT_TRUE(e["t"].is_number());
    EXPECT_TRUE(e["message"].is_string());
    initialized = initialized || e["kind"] == "initialized";
  }
  EXPECT_TRUE(initialized);
}

TEST_F(CliRunEndToEnd, EvaluatesAgainstTheTruth) {
  const auto e = report()["evaluation"];
  ASSERT_TRUE(e.contains("ape_se3")) << e.dump();
  for (const char* stat : {"rmse", "mean", "median", "max", "n"}) {
    EXPECT_TRUE(e["ape_se3"][stat].is_number()) << stat;
  }
  EXPECT_LT(e["ape_se3"]["rmse"].get<double>(), 1.0);
  const io::Dataset ds = io::readDataset(sim_, std::nullopt, {});
  EXPECT_GE(e["ape_se3"]["n"].get<double>(), 0.9 * framesAfterInit(ds));
  // The truth's path over the span of the estimate (the truth is at 100 Hz, the estimate 10 Hz).
  const Trajectory est = io::readTum(run() / "trajectory_vio.tum");
  Trajectory span;
  for (std::size_t i = 0; i < ds.groundtruth->size(); ++i) {
    const std::int64_t t = ds.groundtruth->t_ns[i];
    if (t >= est.t_ns.front() && t <= est.t_ns.back())
      span.poses.push_back(ds.groundtruth->poses[i]);
  }
  EXPECT_NEAR(e["path_length_m"].get<double>(), pathLengthM(span), 0.05);
  EXPECT_TRUE(e["rpe_100m_percent"].is_null());  // shorter than two 100 m segments
  EXPECT_TRUE(fs::exists(run() / "groundtruth.tum"));
  // The summary line names the figure.
  EXPECT_THAT(result_.err, HasSubstr("APE (SE3) rmse"));
}

TEST_F(CliRunEndToEnd, ConfigDumpLoadsBack) {
  const cli::AppConfig c = cli::loadConfig({run() / "config.yaml", {}});
  EXPECT_EQ(cli::dumpConfigYaml(c), cli::dumpConfigYaml(cli::AppConfig{}));
  EXPECT_EQ(c.vio.mode, "auto");
}

}  // namespace
}  // namespace gvio::test
