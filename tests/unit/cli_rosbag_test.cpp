// gvio simulate --format rosbag and gvio run / inspect on the bag (issue 16): the bag and the
// EuRoC folder simulated from one seed give the same run (same calibration, same poses), inspect
// summarises the bag's topics, and a bag without calibration is one line and exit 2.
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

TEST(CliRosbag, TheBagAndTheFolderOfOneSeedGiveTheSameRun) {
  const std::string drive =
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 4", GVIO_SOURCE_DIR);
  const fs::path bag_dir = test::cachedSimulation(drive + " --format rosbag");
  const fs::path folder = test::cachedSimulation(drive + " --format euroc");
  ASSERT_TRUE(fs::exists(bag_dir / "drive.bag"));
  test::TempDir dir("cli_rosbag");
  const std::string calib = "--calib " + test::quoted(bag_dir / "camchain.yaml") + " " +
                            test::quoted(bag_dir / "imu.yaml");
  const auto run = [&](const fs::path& dataset, const std::string& out) {
    return test::runGvio(fmt::format(
        "run --dataset {} {} --out {} --no-progress --gnss graph {} --set map.enabled=false",
        test::quoted(dataset), calib, test::quoted(dir.path() / out), test::kSimGeo));
  };
  const test::CommandResult from_bag = run(bag_dir / "drive.bag", "bag");
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.err;
  const test::CommandResult from_folder = run(folder, "folder");
  ASSERT_EQ(from_folder.exit_code, 0) << from_folder.err;
  for (const char* file : {"trajectory_vio.tum", "trajectory.tum"}) {
    const auto a = test::tumRows(dir.path() / "bag" / file),
               b = test::tumRows(dir.path() / "folder" / file);
    ASSERT_EQ(a.size(), b.size()) << file;
    ASSERT_GT(a.size(), 50U) << file;
    for (std::size_t i = 0; i < a.size(); ++i) {
      for (std::size_t k = 0; k < a[i].size(); ++k)
        EXPECT_NEAR(a[i][k], b[i][k], 1e-9) << file << i;
    }
  }
  const auto report = nlohmann::json::parse(test::readText(dir.path() / "bag" / "report.json"));
  EXPECT_EQ(report["dataset"]["format"], "rosbag");
  EXPECT_EQ(report["mode"], "stereo-imu");
  const auto& topics = report["dataset"]["bag_topics"];
  ASSERT_EQ(topics.size(), 4U);  // two cameras, IMU, GNSS
  EXPECT_EQ(topics[0]["topic"], "/cam0/image_raw");
  EXPECT_EQ(topics[1]["topic"], "/cam1/image_raw");
  EXPECT_EQ(topics[2]["role"], "imu");
  EXPECT_EQ(topics[2]["used"], topics[2]["messages"]);
  EXPECT_EQ(topics[3]["type"], "sensor_msgs/NavSatFix");
  EXPECT_EQ(report["gnss"]["fixes"], report["dataset"]["gnss_fixes"]);
  EXPECT_GE(report["dataset"]["gnss_fixes"].get<int>(), 8);

  const test::CommandResult inspect = test::runGvio(
      fmt::format("inspect --dataset {} --no-progress", test::quoted(bag_dir / "drive.bag")));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_THAT(inspect.out, HasSubstr("dataset   rosbag"));
  EXPECT_THAT(inspect.out, HasSubstr("topic     imu  /imu0 (sensor_msgs/Imu)"));
  EXPECT_THAT(inspect.out, HasSubstr("a bag holds no camera calibration"));

  const test::CommandResult uncalibrated = test::runGvio(
      fmt::format("run --dataset {} --out {} --no-progress", test::quoted(bag_dir / "drive.bag"),
                  test::quoted(dir.path() / "none")));
  EXPECT_EQ(uncalibrated.exit_code, 2);
  EXPECT_THAT(uncalibrated.err,
              HasSubstr("drive.bag: a bag holds no camera calibration: give --calib"));
  EXPECT_EQ(std::count(uncalibrated.err.begin(), uncalibrated.err.end(), '\n'), 1)
      << uncalibrated.err;
}

}  // namespace
}  // namespace gvio
