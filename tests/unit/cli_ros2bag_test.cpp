// gvio simulate --format ros2bag and gvio run / inspect on ROS 2 bags (issue 60): one seed read
// from the MCAP file, the .db3 file and the bag folder gives the EuRoC folder's run; the
// calibration the bag carries (CameraInfo + /tf_static) gives the run Kalibr files of the same
// values give; inspect says where each calibration value came from.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "support/fixtures.hpp"

namespace gvio {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

double maxDifference(const fs::path& a_file, const fs::path& b_file) {
  const auto a = test::tumRows(a_file), b = test::tumRows(b_file);
  EXPECT_EQ(a.size(), b.size()) << a_file << " vs " << b_file;
  EXPECT_GT(a.size(), 50U) << a_file;
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    for (std::size_t k = 0; k < a[i].size(); ++k)
      worst = std::max(worst, std::abs(a[i][k] - b[i][k]));
  }
  return worst;
}

const std::string kDrive =
    fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 4", GVIO_SOURCE_DIR);

TEST(CliRos2Bag, McapSqliteAndTheFolderGiveTheEurocRun) {
  const fs::path mcap = test::cachedSimulation(kDrive + " --format ros2bag");
  const fs::path db3 =
      test::cachedSimulation(kDrive + " --format ros2bag --set sim.ros2bag_storage=sqlite3");
  const fs::path euroc = test::cachedSimulation(kDrive + " --format euroc");
  ASSERT_TRUE(fs::exists(mcap / "drive_0.mcap"));
  ASSERT_TRUE(fs::exists(db3 / "drive_0.db3"));
  test::TempDir dir("cli_ros2bag");
  // The bag carries the cameras; the IMU's noise has no place in a bag (imu.yaml).
  const auto run = [&](const fs::path& dataset, const std::string& calib, const std::string& out) {
    const test::CommandResult r = test::runGvio(fmt::format(
        "run --dataset {} {} --out {} --no-progress --gnss graph {} --set map.enabled=false",
        test::quoted(dataset), calib, test::quoted(dir.path() / out), test::kSimGeo));
    EXPECT_EQ(r.exit_code, 0) << out << ": " << r.err;
    return dir.path() / out;
  };
  const std::string imu_only = "--calib " + test::quoted(mcap / "imu.yaml");
  const fs::path from_euroc = run(euroc, "", "euroc");
  const fs::path from_folder = run(mcap, imu_only, "folder");
  const fs::path from_mcap = run(mcap / "drive_0.mcap", imu_only, "mcap");
  const fs::path from_db3 = run(db3 / "drive_0.db3", imu_only, "db3");
  const std::string kalibr =
      "--calib " + test::quoted(mcap / "camchain.yaml") + " " + test::quoted(mcap / "imu.yaml");
  const fs::path from_kalibr = run(mcap, kalibr, "kalibr");
  // The ROS 1 bag of the same seed, with the same Kalibr files.
  const fs::path ros1 = test::cachedSimulation(kDrive + " --format rosbag");
  const fs::path from_ros1 = run(ros1 / "drive.bag", kalibr, "ros1");
  // And the EuRoC folder given the same Kalibr files (which replace its sensor.yaml's cameras).
  const fs::path from_euroc_kalibr = run(euroc, kalibr, "euroc_kalibr");
  for (const char* file : {"trajectory_vio.tum", "trajectory.tum"}) {
    // The storages and the folder: the same bytes; so are ROS 2, ROS 1 and the EuRoC folder given
    // one calibration.
    EXPECT_EQ(test::readText(from_folder / file), test::readText(from_mcap / file)) << file;
    EXPECT_EQ(test::readText(from_folder / file), test::readText(from_db3 / file)) << file;
    EXPECT_EQ(test::readText(from_kalibr / file), test::readText(from_ros1 / file)) << file;
    EXPECT_EQ(test::readText(from_kalibr / file), test::readText(from_euroc_kalibr / file)) << file;
    // The calibration's own representations differ in their last bits (a quaternion in
    // /tf_static, 12 decimals in EuRoC's sensor.yaml, Kalibr's inverted T_cam_imu): the poses
    // then agree to one unit of the last digit TUM prints (1e-9, parsed back with its rounding).
    EXPECT_LT(maxDifference(from_folder / file, from_euroc / file), 1.5e-9) << file;
    EXPECT_LT(maxDifference(from_folder / file, from_kalibr / file), 1.5e-9) << file;
  }
  const auto report = nlohmann::json::parse(test::readText(from_folder / "report.json"));
  EXPECT_EQ(report["dataset"]["format"], "ros2bag");
  EXPECT_EQ(report["mode"], "stereo-imu");
}

TEST(CliRos2Bag, InspectSaysWhereEachCalibrationValueCameFrom) {
  const fs::path mcap = test::cachedSimulation(kDrive + " --format ros2bag");
  const test::CommandResult inspect =
      test::runGvio(fmt::format("inspect --dataset {} --no-progress --quick", test::quoted(mcap)));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_THAT(inspect.out, HasSubstr("dataset   ros2bag (ROS 2 bag, mcap, 2 camera(s))"));
  EXPECT_THAT(inspect.out, HasSubstr("topic     imu  /imu0 (sensor_msgs/Imu)"));
  EXPECT_THAT(inspect.out,
              HasSubstr("calib     cam0 intrinsics  from /cam0/camera_info (plumb_bob"));
  EXPECT_THAT(inspect.out, HasSubstr("calib     T_b_cam1         from /tf_static: imu -> cam1"));
  EXPECT_THAT(inspect.out, HasSubstr("calib     GNSS lever arm   from /tf_static: imu -> gnss"));
  EXPECT_THAT(inspect.out, HasSubstr("GNSS antenna in the body frame [0.000 0.000 0.800] m"));
  // Kalibr files replace the bag's cameras, and say so.
  const test::CommandResult kalibr =
      test::runGvio(fmt::format("inspect --dataset {} --calib {} --no-progress --quick",
                                test::quoted(mcap), test::quoted(mcap / "camchain.yaml")));
  ASSERT_EQ(kalibr.exit_code, 0) << kalibr.err;
  EXPECT_THAT(kalibr.out, HasSubstr("calib     cam0 intrinsics  from --calib"));
}

}  // namespace
}  // namespace gvio
