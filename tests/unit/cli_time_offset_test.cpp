// Camera-IMU time offset (issue 16): a simulated camera that stamps its images 20 ms after the
// exposure costs accuracy; Kalibr's timeshift_cam_imu of -20 ms gives back the synchronised run
// exactly; the online estimate is reported in report.json.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
  const auto sync = run(synced, "zero.yaml", "sync");
  const auto ignored = run(lagging, "zero.yaml", "ignored");
  const auto shifted = run(lagging, "shift.yaml", "shifted");
  const double ape_sync = sync["evaluation"]["ape_se3"]["rmse"].get<double>();
  const double ape_ignored = ignored["evaluation"]["ape_se3"]["rmse"].get<double>();
  EXPECT_GT(ape_ignored, 1.3 * ape_sync) << ape_sync;
  // The stamps moved back by the shift are the exposures: the synchronised run, bit for bit.
  EXPECT_EQ(test::readText(dir.path() / "shifted" / "trajectory_vio.tum"),
            test::readText(dir.path() / "sync" / "trajectory_vio.tum"));
  EXPECT_DOUBLE_EQ(shifted["time_offset"]["calibration_timeshift_cam_imu_s"].get<double>(), -0.02);
  EXPECT_FALSE(shifted["time_offset"]["estimated"].get<bool>());  // off by default
  EXPECT_EQ(shifted["time_offset"]["t_d_s"].get<double>(), 0.0);

  const auto estimated =
      run(lagging, "zero.yaml", "estimated", "--set vio.estimate_time_offset=true");
  const auto& t = estimated["time_offset"];
  EXPECT_TRUE(t["estimated"].get<bool>());
  EXPECT_GE(t["history"].size(), 8U);  // one value per second once initialised
  EXPECT_NE(t["t_d_s"].get<double>(), 0.0);
  EXPECT_LT(std::abs(t["t_d_s"].get<double>()), 0.05);
  EXPECT_DOUBLE_EQ(t["stamp_lag_s"].get<double>(), t["t_d_s"].get<double>());
}

}  // namespace
}  // namespace gvio
