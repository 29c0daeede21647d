// The fault matrix on ROS 2 bags (issue 60): a truncated .mcap is read up to the cut with a
// warning; a chunk whose CRC fails, a missing split file, a topic of another type and a bag whose
// tf tree does not reach its cameras each stop the run with one line naming the file (exit 2).
#include <algorithm>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <nlohmann/json.hpp>

#include "faults/fault_support.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kDrive =
    fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 4", GVIO_SOURCE_DIR);

// A copy of the simulated bag folder (MCAP or sqlite3) to damage.
class Ros2Case {
 public:
  Ros2Case(const std::string& tag, const std::string& storage) : dir_("fault_ros2_" + tag) {
    const std::string args =
        kDrive + " --format ros2bag" +
        (storage == "sqlite3" ? " --set sim.ros2bag_storage=sqlite3" : std::string());
    fs::copy(cachedSimulation(args), bag(), fs::copy_options::recursive);
  }
  [[nodiscard]] fs::path bag() const { return dir_.path() / "bag"; }
  [[nodiscard]] fs::path out() const { return dir_.path() / "run"; }
  CommandResult run(const std::string& extra = "") const {
    return runGvio(runArgs(bag(), out()) + " --calib " + quoted(bag() / "imu.yaml") + " " + extra);
  }

 private:
  TempDir dir_;
};

void expectRefused(const Ros2Case& c, const CommandResult& r, const fs::path& file,
                   const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const std::string line = errorLine(r);
  EXPECT_THAT(line, HasSubstr(file.string())) << line;
  EXPECT_THAT(line, HasSubstr(what));
  EXPECT_FALSE(fs::exists(c.out())) << "a refused run wrote a folder";
}

TEST(FaultRos2, TruncatedMcapIsReadUpToTheCut) {
  const Ros2Case c("truncated", "mcap");
  const fs::path file = c.bag() / "drive_0.mcap";
  fs::resize_file(file, fs::file_size(file) * 6 / 10);
  const CommandResult r = c.run();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr(file.string() + ": cut short"));
  EXPECT_EQ(reportStatus(c.out()), "complete");
  expectFiniteOutputs(c.out());
  expectNoTemporaries(c.out());
  const auto report = nlohmann::json::parse(readText(c.out() / "report.json"));
  const auto& warnings = report["dataset"]["warnings"];
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(), [&](const auto& w) {
    return w.template get<std::string>().find(file.string() + ": cut short") == 0;
  })) << warnings.dump();
  const auto& topics = report["dataset"]["bag_topics"];
  ASSERT_EQ(topics.size(), 4U);
  EXPECT_GT(topics[0]["messages"].get<int>(), 30);  // what was before the cut
  EXPECT_LT(topics[0]["messages"].get<int>(), 60);
}

TEST(FaultRos2, ChunkFailingItsCheckIsRefused) {
  const Ros2Case c("crc", "mcap");
  const fs::path file = c.bag() / "drive_0.mcap";
  std::string bytes = readText(file);
  for (std::size_t i = bytes.size() / 2; i < bytes.size() / 2 + 64; ++i) bytes[i] ^= 0x5A;
  writeText(file, bytes);
  expectRefused(c, c.run(), file, "chunk at byte");
}

TEST(FaultRos2, MissingSplitFileIsRefused) {
  const Ros2Case c("split", "mcap");
  const fs::path meta = c.bag() / "metadata.yaml";
  std::string text = readText(meta);
  const std::string listed = "  relative_file_paths:\n    - drive_0.mcap\n";
  ASSERT_NE(text.find(listed), std::string::npos);
  text.replace(text.find(listed), listed.size(), listed + "    - drive_1.mcap\n");
  writeText(meta, text);
  expectRefused(c, c.run(), meta, "lists storage file drive_1.mcap, which is missing");
}

TEST(FaultRos2, TopicOfAnotherTypeIsRefused) {
  const Ros2Case c("type", "mcap");
  expectRefused(c, c.run("--set dataset.topics.imu=/gnss/fix"), c.bag(),
                "topic /gnss/fix is sensor_msgs/msg/NavSatFix, not sensor_msgs/msg/Imu");
}

TEST(FaultRos2, TfTreeNotReachingTheCamerasIsRefused) {
  const Ros2Case c("tf", "sqlite3");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((c.bag() / "drive_0.db3").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "DELETE FROM messages WHERE topic_id = "
                         "(SELECT id FROM topics WHERE name = '/tf_static')",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  expectRefused(c, c.run(), c.bag(),
                "the bag does not calibrate its cameras (no tf path from the body frame 'imu' "
                "to camera frame 'cam0'");
}

}  // namespace
}  // namespace gvio::test
