// Camera-IMU time offset (issue 16): a simulated camera that stamps its images 20 ms after the
// exposure costs accuracy; Kalibr's timeshift_cam_imu of -20 ms gives back the synchronised run
// exactly; the online estimate is reported in report.json.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <algorithm>

#include <cmath>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"
#include "io/kalibr_writer.hpp"
#include "support/fixtures.hpp"

namespace gvio {
namespace {
namespace fs = std::filesystem;

TEST(CliTimeOffset, KalibrTimeshiftUndoesALaggingCameraAndTheEstimateIsReported) {
  const std::string drive =
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 6 --format euroc",
                  GVIO_SOURCE_DIR);
  const fs::path synced = test::cachedSimulation(drive);
  const fs::path lagging = test::cachedSimulation(drive + " --set sim.camera_time_offset_s=0.02");
  const io::Dataset ds = io::readDataset(synced, std::nullopt, io::ReaderConfig{});
  ASSERT_EQ(ds.cameras.size(), 2U);
  test::TempDir dir("cli_time_offset");
  const std::vector<std::string> topics = {"/cam0", "/cam1"};
  test::writeText(dir.path() / "zero.yaml", io::kalibrCamchainYaml(ds.cameras, topics, 0.0));
  test::writeText(dir.path() / "shift.yaml", io::kalibrCamchainYaml(ds.cameras, topics, -0.02));
  const auto run = [&](const fs::path& dataset, const std::string& calib, const std::string& out,
                       const std::string& extra = "") {
    const test::CommandResult r = test::runGvio(fmt::format(
        "run --dataset {} --calib {} --out {} --no-progress --gnss off --set map.enabled=false "
        "--set loops.enabled=false {}",
        test::quoted(dataset), test::quoted(dir.path() / calib), test::quoted(dir.path() / out),
        extra));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(test::readText(dir.path() / out / "report.json"));
  };
  // The estimate is on by default.
  const auto sync = run(synced, "zero.yaml", "sync");
  const auto ignored = run(lagging, "zero.yaml", "ignored", "--set vio.estimate_time_offset=false");
  const auto shifted = run(lagging, "shift.yaml", "shifted");
  const auto estimated = run(lagging, "zero.yaml", "estimated");
  const auto ape = [](const nlohmann::json& report) {
    return report["evaluation"]["ape_se3"]["rmse"].get<double>();
  };
  // Measured (2026-11-27, with t_d held on the straights): synchronised 0.170 m, lagging 0.235 m
  // unestimated, 0.161 m estimated; with the full-resolution KLT pass 0.072 m and 0.071 m
  // estimated. Since each observation is counted once (2026-11-29): synchronised 0.059 m,
  // lagging 0.315 m unestimated and 0.070 m estimated, +18 % (t_d jumped by -13 ms at the
  // turn's exit in both runs). With the hold keeping the median of the last free solves
  // (2026-11-30): synchronised 0.061 m, lagging 0.298 m unestimated and 0.066 m estimated, +9 %
  // (docs/how-it-works/time-offset.md). The bound keeps the estimate from falling further behind.
  EXPECT_GT(ape(ignored), 1.3 * ape(estimated)) << ape(estimated);
  EXPECT_LT(ape(estimated), 1.2 * ape(sync)) << ape(sync);
  // The stamps moved back by the shift are the exposures: the synchronised run, bit for bit.
  EXPECT_EQ(test::readText(dir.path() / "shifted" / "trajectory_vio.tum"),
            test::readText(dir.path() / "sync" / "trajectory_vio.tum"));
  EXPECT_DOUBLE_EQ(shifted["time_offset"]["calibration_timeshift_cam_imu_s"].get<double>(), -0.02);
  EXPECT_FALSE(ignored["time_offset"]["estimated"].get<bool>());
  EXPECT_EQ(ignored["time_offset"]["t_d_s"].get<double>(), 0.0);
  EXPECT_EQ(ignored["time_offset"]["status"], "not estimated");

  const auto& t = estimated["time_offset"];
  EXPECT_TRUE(t["estimated"].get<bool>());
  EXPECT_GE(t["history"].size(), 8U);  // one value per second once initialised
  EXPECT_NE(t["t_d_s"].get<double>(), 0.0);
  EXPECT_LT(std::abs(t["t_d_s"].get<double>()), 0.05);
  EXPECT_DOUBLE_EQ(t["stamp_lag_s"].get<double>(), t["t_d_s"].get<double>());

  // The drive's first 9.8 s are straight at a constant 8 m/s, where t_d is unobservable: it is
  // held there, not left to wander (before the hold the synchronised run's estimate went to -25.6
  // ms within 4 s and ended at -10.0 ms; measured with it: 0 all the way, -0.5 ms at the end).
  const auto& history = sync["time_offset"]["history"];
  ASSERT_GE(history.size(), 8U);
  const double t0 = history[0][0].get<double>();
  for (const auto& entry : history) {
    if (entry[0].get<double>() - t0 > 8.0) break;
    EXPECT_EQ(entry[1].get<double>(), history[0][1].get<double>()) << entry;
  }
  // It ends where the exit of the drive's one turn (15 s) leaves it before the final straight
  // holds it: -0.5 ms before the tracker's full-resolution KLT pass (2026-11-27), -11.3 ms with it
  // (one solve at 14.4 s, the last weakly excited window before the hold, moved it); since the
  // hold keeps the median of the last free solves, -0.3 ms (2026-11-30).
  EXPECT_LT(std::abs(sync["time_offset"]["t_d_s"].get<double>()), 0.003);
  // The lag is estimated to within 1 ms at the end (19.3 ms), though not after 10 s: the drive
  // turns only from 9.8 s on.
  EXPECT_NEAR(t["t_d_s"].get<double>(), 0.02, 0.001);
  EXPECT_GE(sync["time_offset"]["held_solves"].get<int>(), 50);
  // Observed in the turn: an estimate with the spread of its late free solves.
  EXPECT_EQ(t["status"], "estimated");
  EXPECT_LT(t["sigma_s"].get<double>(), 0.005);
}

// The hold keeps the median of the latest free solves' t_d, not the last one's. With a 15 px KLT
// window and 4 pyramid levels the synchronised demo drive's last free solve before the final
// straight (14.4 s, the turn's exit, weakly excited) moves t_d from -3.8 to -16.1 ms, and the
// next solve, were it free, would bring it back to +0.3 ms (measured 2026-11-30 with the hold
// off). Holding the last value kept -16.1 ms for the rest of the drive
// (`vio.time_offset_hold_median_solves=1`); the median of the last ten keeps -0.9 ms.
TEST(CliTimeOffset, AHoldKeepsTheMedianOfTheLastFreeSolvesNotAnOutlier) {
  const fs::path synced = test::cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 6 --format euroc",
                  GVIO_SOURCE_DIR));
  test::TempDir dir("cli_time_offset_median");
  const test::CommandResult r = test::runGvio(fmt::format(
      "run --dataset {} --out {} --no-progress --gnss off --set map.enabled=false --set "
      "loops.enabled=false --set vio.tracker.klt_window_px=15 --set vio.tracker.klt_levels=4",
      test::quoted(synced), test::quoted(dir.path() / "out")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::readText(dir.path() / "out" / "report.json"));
  EXPECT_GE(report["time_offset"]["held_solves"].get<int>(), 50);
  EXPECT_LT(std::abs(report["time_offset"]["t_d_final_s"].get<double>()), 0.003);
}

// The demo drive's first 9 s are straight at a constant 8 m/s: the offset is held in nearly every
// solve, and the run says "not observed" instead of printing the prior's value as an estimate.
TEST(CliTimeOffset, AStraightSteadyDriveSaysNotObserved) {
  const fs::path straight = test::cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 9 --seed 6 --format euroc",
                  GVIO_SOURCE_DIR));
  test::TempDir dir("cli_time_offset_straight");
  const test::CommandResult r = test::runGvio(fmt::format(
      "run --dataset {} --out {} --no-progress --gnss off --set map.enabled=false --set "
      "loops.enabled=false",
      test::quoted(straight), test::quoted(dir.path() / "out")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::readText(dir.path() / "out" / "report.json"));
  EXPECT_EQ(report["time_offset"]["status"], "not observed") << report["time_offset"].dump();
  EXPECT_TRUE(report["time_offset"]["sigma_s"].is_null());
  const auto at = r.err.find("camera-IMU time offset not observed");
  ASSERT_NE(at, std::string::npos) << r.err;
  std::printf("straight 9 s: %s\n", r.err.substr(at, r.err.find_first_of(";\n", at) - at).c_str());
}

// A slalom (6 m/s, +-1 m at 0.4 Hz, yaw rate up to 1 rad/s) excites the time offset from the
// start, unlike a straight car drive on which it is unobservable
// (docs/how-it-works/time-offset.md). With stamps 20 ms late, the estimate must come close to 20 ms
// and give back most of the APE the lag costs.
TEST(CliTimeOffset, AnExcitedDriveEstimatesTheLagAndRecoversTheTrajectory) {
  test::TempDir dir("cli_time_offset_slalom");
  const fs::path trajectory = fs::path(GVIO_TEST_CACHE_DIR) / "slalom_6mps_10s.tum";
  std::string tum;
  for (int i = 0; i <= 1100; ++i) {
    const double t = 0.01 * i;
    const double w = 2.0 * M_PI * 0.4;
    const double yaw = std::atan2(w * std::cos(w * t), 6.0);
    tum += fmt::format("{:.6f} {:.6f} {:.6f} 0.93 0 0 {:.9f} {:.9f}\n", 1317646534.0 + t, 6.0 * t,
                       std::sin(w * t), std::sin(0.5 * yaw), std::cos(0.5 * yaw));
  }
  fs::create_directories(trajectory.parent_path());
  test::writeText(trajectory, tum);
  const fs::path lagging =
      test::cachedSimulation(fmt::format("--trajectory {} --seconds 10 --seed 6 --format euroc "
                                         "--set sim.camera_time_offset_s=0.02",
                                         test::quoted(trajectory)));
  const auto run = [&](const std::string& out, bool estimate) {
    const test::CommandResult r = test::runGvio(
        fmt::format("run --dataset {} --out {} --no-progress --gnss off --set map.enabled=false "
                    "--set loops.enabled=false --set vio.estimate_time_offset={}",
                    test::quoted(lagging), test::quoted(dir.path() / out), estimate));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(test::readText(dir.path() / out / "report.json"));
  };
  const auto off = run("off", false);
  const auto on = run("on", true);
  const double ape_off = off["evaluation"]["ape_se3"]["rmse"].get<double>();
  const double ape_on = on["evaluation"]["ape_se3"]["rmse"].get<double>();
  // Measured (2026-11-27, before the full-resolution KLT pass): 2.34 m off, 0.049 m on (0.030 m
  // with that pass); the initialisation's t_d 20.3 +- 0.5 ms, the
  // window re-timed to it and aligned again, then 19.9-20.2 ms throughout. (Without the second
  // alignment 0.065 m, 15.2 ms after 1 s; without any re-timing 0.11 m and 17.3-18.7 ms.)
  EXPECT_LT(ape_on, 0.04 * ape_off) << ape_on << " vs " << ape_off;
  EXPECT_NEAR(on["time_offset"]["t_d_s"].get<double>(), 0.02, 0.001);  // the 1 ms
  // Every second's value within 1 ms before the tracker's full-resolution KLT pass; with it all
  // but one (21.3 ms at 8 s) are, and the APE fell from 0.049 to 0.030 m. Since each observation
  // is counted once (2026-11-29) that one is 22.2 ms (21.1 ms re-anchoring the folded landmarks),
  // the others 19.6-20.2 ms, the APE 0.033 m.
  double lowest = 1.0, highest = -1.0;
  for (const auto& entry : on["time_offset"]["history"]) {
    lowest = std::min(lowest, entry[1].get<double>());
    highest = std::max(highest, entry[1].get<double>());
  }
  std::printf(
      "slalom, 20 ms lag: APE %.3f m (%.3f m with the estimate off); t_d reported %.1f +- %.1f ms, "
      "last %.1f ms, each second's %.1f-%.1f ms\n",
      ape_on, ape_off, 1e3 * on["time_offset"]["t_d_s"].get<double>(),
      1e3 * on["time_offset"]["sigma_s"].get<double>(),
      1e3 * on["time_offset"]["t_d_final_s"].get<double>(), 1e3 * lowest, 1e3 * highest);
  int off_by_over_1ms = 0;
  for (const auto& entry : on["time_offset"]["history"]) {
    EXPECT_NEAR(entry[1].get<double>(), 0.02, 0.0025) << entry;
    off_by_over_1ms += std::abs(entry[1].get<double>() - 0.02) > 0.001 ? 1 : 0;
  }
  EXPECT_LE(off_by_over_1ms, 1);
  EXPECT_EQ(on["time_offset"]["held_solves"].get<int>(), 0);  // excited all the way
  EXPECT_EQ(on["time_offset"]["status"], "estimated");
  EXPECT_LT(on["time_offset"]["sigma_s"].get<double>(), 0.002);
}

}  // namespace
}  // namespace gvio
