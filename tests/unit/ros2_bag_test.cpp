// ROS 2 bags (issue 60): the bag folder and its storage files (sqlite3 and MCAP, split bags,
// per-message zstd), the tf tree, and the calibration a bag carries (CameraInfo + /tf_static).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zstd.h>

#include <Eigen/Geometry>
#include <array>
#include <fstream>

#include "io/input_error.hpp"
#include "io/ros2/ros2_bag.hpp"
#include "io/ros2/ros2_bag_writer.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros2/tf_tree.hpp"
#include "io/ros2_dataset.hpp"
#include "support/fixtures.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

std::vector<std::uint8_t> imuBytes(std::int64_t t_ns, double gyr_x) {
  Ros2Imu m;
  m.imu.t.header_ns = t_ns;
  m.imu.gyr_radps = {gyr_x, 0.0, 0.0};
  m.imu.acc_mps2 = {0.0, 0.0, 9.81};
  m.frame_id = "imu";
  return encodeImu(m);
}

// A bag of `count` IMU messages (1 ms apart from `t0_ns`) on /imu in `folder`.
void writeImuBag(const fs::path& folder, Ros2Storage storage, std::int64_t t0_ns, int count,
                 const std::string& compression = "lz4") {
  fs::create_directories(folder);
  Ros2BagWriter writer(folder, "drive", storage, compression);
  const std::size_t imu = writer.addTopic("/imu", kRos2ImuType);
  for (int i = 0; i < count; ++i) {
    const std::int64_t t = t0_ns + i * 1'000'000;
    writer.write(imu, t, imuBytes(t, 0.001 * i));
  }
  writer.close();
}

TEST(Ros2Bag, ReadsBothStoragesAsOneRecording) {
  test::TempDir dir("ros2_bag_storages");
  for (const Ros2Storage storage : {Ros2Storage::kMcap, Ros2Storage::kSqlite3}) {
    const fs::path folder = dir.path() / (storage == Ros2Storage::kMcap ? "mcap" : "db3");
    writeImuBag(folder, storage, 1'000'000'000, 50);
    const Ros2Bag bag(folder);
    EXPECT_EQ(bag.storage(), storage == Ros2Storage::kMcap ? "mcap" : "sqlite3");
    ASSERT_EQ(bag.topics().size(), 1U);
    const Ros2Topic& t = bag.topics()[0];
    EXPECT_EQ(t.name, "/imu");
    EXPECT_EQ(t.type, kRos2ImuType);
    ASSERT_EQ(t.messages.size(), 50U);
    for (std::size_t i = 0; i < 50; ++i) {
      const auto expected_t = 1'000'000'000 + static_cast<std::int64_t>(i) * 1'000'000;
      EXPECT_EQ(bag.logTimeNs(t, i), expected_t);
      EXPECT_EQ(bag.headerStampNs(t, i), expected_t);
      const std::vector<std::uint8_t> bytes = bag.read(t, i);
      EXPECT_EQ(decodeImu(bytes).imu.gyr_radps[0], 0.001 * static_cast<double>(i));
    }
    // The storage file alone is the same recording.
    const fs::path file = folder / (storage == Ros2Storage::kMcap ? "drive_0.mcap" : "drive_0.db3");
    EXPECT_TRUE(looksLikeRos2Bag(file));
    EXPECT_EQ(Ros2Bag(file).topics()[0].messages.size(), 50U);
  }
}

// A split bag: metadata.yaml listing two files; topics are joined in the files' order.
fs::path writeSplitBag(const fs::path& dir) {
  writeImuBag(dir / "a", Ros2Storage::kMcap, 1'000'000'000, 30);
  writeImuBag(dir / "b", Ros2Storage::kMcap, 2'000'000'000, 20);
  const fs::path bag = dir / "split";
  fs::create_directories(bag);
  fs::rename(dir / "a" / "drive_0.mcap", bag / "split_0.mcap");
  fs::rename(dir / "b" / "drive_0.mcap", bag / "split_1.mcap");
  test::writeText(bag / "metadata.yaml",
                  "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n"
                  "  relative_file_paths:\n    - split_0.mcap\n    - split_1.mcap\n"
                  "  compression_format: \"\"\n  compression_mode: \"\"\n");
  return bag;
}

TEST(Ros2Bag, JoinsTheFilesOfASplitBag) {
  test::TempDir dir("ros2_bag_split");
  const fs::path bag_dir = writeSplitBag(dir.path());
  const Ros2Bag bag(bag_dir);
  ASSERT_EQ(bag.files().size(), 2U);
  const Ros2Topic& t = bag.topics().at(0);
  ASSERT_EQ(t.messages.size(), 50U);
  EXPECT_EQ(bag.logTimeNs(t, 29), 1'029'000'000);
  EXPECT_EQ(bag.logTimeNs(t, 30), 2'000'000'000);

  // Without metadata.yaml: the folder's files in split order, with a warning.
  fs::remove(bag_dir / "metadata.yaml");
  const Ros2Bag listed(bag_dir);
  EXPECT_EQ(listed.topics().at(0).messages.size(), 50U);
  ASSERT_EQ(listed.warnings().size(), 1U);
  EXPECT_THAT(listed.warnings()[0], HasSubstr("no metadata.yaml"));
}

TEST(Ros2Bag, AMissingSplitFileIsOneLineNamingIt) {
  test::TempDir dir("ros2_bag_missing");
  const fs::path bag_dir = writeSplitBag(dir.path());
  fs::remove(bag_dir / "split_1.mcap");
  try {
    const Ros2Bag bag(bag_dir);
    FAIL() << "a missing split file was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("metadata.yaml"));
    EXPECT_THAT(e.what(), HasSubstr("split_1.mcap, which is missing"));
  }
}

TEST(Ros2Bag, DecompressesMessagesCompressedOneByOne) {
  test::TempDir dir("ros2_bag_zstd");
  const fs::path bag_dir = dir.path() / "bag";
  fs::create_directories(bag_dir);
  {
    Ros2BagWriter writer(bag_dir, "drive", Ros2Storage::kSqlite3, "none");
    const std::size_t imu = writer.addTopic("/imu", kRos2ImuType);
    for (int i = 0; i < 5; ++i) {
      const std::vector<std::uint8_t> raw = imuBytes(i * 1'000'000LL, 0.5 * i);
      std::vector<std::uint8_t> packed(ZSTD_compressBound(raw.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 1));
      writer.write(imu, i * 1'000'000LL, packed);
    }
    writer.close();
  }
  std::string meta = test::readText(bag_dir / "metadata.yaml");
  const auto set = [&](const std::string& from, const std::string& to) {
    meta.replace(meta.find(from), from.size(), to);
  };
  set("compression_format: \"\"", "compression_format: zstd");
  set("compression_mode: \"\"", "compression_mode: MESSAGE");
  test::writeText(bag_dir / "metadata.yaml", meta);
  const Ros2Bag bag(bag_dir);
  const Ros2Topic& t = bag.topics().at(0);
  EXPECT_EQ(bag.headerStampNs(t, 3), 3'000'000);
  EXPECT_EQ(decodeImu(bag.read(t, 4)).imu.gyr_radps[0], 2.0);

  set("MESSAGE", "FILE");
  test::writeText(bag_dir / "metadata.yaml", meta);
  EXPECT_THROW({ const Ros2Bag refused(bag_dir); }, InputError);
}

TEST(Ros2Bag, RefusesWhatIsNotABag) {
  test::TempDir dir("ros2_bag_not");
  test::writeText(dir.path() / "x.db3", "not a database at all, just some text for the reader");
  EXPECT_THROW({ const Ros2Bag bag(dir.path() / "x.db3"); }, InputError);
  test::writeText(dir.path() / "metadata.yaml", "something: else\n");
  try {
    const Ros2Bag bag(dir.path());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not a ROS 2 bag"));
  }
}

// The attitude an Imu message reports is kept when its covariance states a yaw sigma (Imu.msg:
// element 0 = -1 means none; all zeros, "unknown", is no sigma either).
TEST(Ros2Bag, ImuOrientationWithAStatedYawSigmaIsKept) {
  test::TempDir dir("ros2_bag_attitude");
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  const std::array<std::array<double, 9>, 3> covariances = {
      std::array<double, 9>{0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.0025}, std::array<double, 9>{-1.0},
      std::array<double, 9>{}};
  for (std::size_t k = 0; k < covariances.size(); ++k) {
    const fs::path folder = dir.path() / std::to_string(k);
    fs::create_directories(folder);
    {
      Ros2BagWriter writer(folder, "drive", Ros2Storage::kMcap, "none");
      const std::size_t imu = writer.addTopic("/imu", kRos2ImuType);
      for (int i = 0; i < 5; ++i) {
        Ros2Imu m;
        m.imu.t.header_ns = 1'000'000'000 + i * 10'000'000LL;
        m.imu.acc_mps2 = {0.0, 0.0, 9.81};
        m.imu.orientation_xyzw = {q.x(), q.y(), q.z(), q.w()};
        m.imu.orientation_covariance = covariances[k];
        writer.write(imu, m.imu.t.header_ns, encodeImu(m));
      }
      writer.close();
    }
    const Dataset ds = readRos2Bag(folder, ReaderConfig{});
    ASSERT_EQ(ds.imu.size(), 5U);
    if (k > 0) {
      EXPECT_TRUE(ds.imu_attitude.empty()) << k;
      continue;
    }
    ASSERT_EQ(ds.imu_attitude.size(), 5U);
    EXPECT_EQ(ds.imu_attitude[2].t_ns, ds.imu[2].t_ns);
    EXPECT_DOUBLE_EQ(ds.imu_attitude[2].yaw_sigma_rad, 0.05);
    EXPECT_LT((ds.imu_attitude[2].R_enu_b - q.toRotationMatrix()).norm(), 1e-12);
  }
}

// A channel whose schema says Imu but whose messages are NavSatFix: refused naming the message.
TEST(Ros2Bag, AMessageOfAnotherTypeThanItsSchemaIsRefused) {
  test::TempDir dir("ros2_bag_schema");
  {
    Ros2BagWriter writer(dir.path(), "drive", Ros2Storage::kMcap, "none");
    const std::size_t imu = writer.addTopic("/imu", kRos2ImuType);
    Ros2NavSatFix fix;
    fix.fix.t.header_ns = 1'000'000'000;
    fix.frame_id = "gps";
    writer.write(imu, 1'000'000'000, encodeNavSatFix(fix));
    writer.close();
  }
  try {
    (void)readRos2Bag(dir.path(), ReaderConfig{});
    FAIL() << "a NavSatFix was read as an Imu";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(dir.path().string() + ": topic /imu: message 0: "));
  }
}

Eigen::Isometry3d pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

TEST(TfTree, ComposesChainsInEitherDirection) {
  TfTree tree;
  const Eigen::Isometry3d T_base_imu = pose(0.1, {0.2, 0.0, 0.5});
  const Eigen::Isometry3d T_base_cam = pose(-0.3, {1.0, 0.1, 1.2});
  const Eigen::Isometry3d T_cam_opt = pose(1.2, {0.0, 0.0, 0.0});
  EXPECT_FALSE(tree.add({"base_link", "imu", T_base_imu, "/tf_static"}));
  EXPECT_FALSE(tree.add({"/base_link", "cam", T_base_cam, "/tf_static"}));
  EXPECT_FALSE(tree.add({"cam", "cam_optical", T_cam_opt, "/tf"}));
  const auto path = tree.lookup("imu", "cam_optical");
  ASSERT_TRUE(path);
  const Eigen::Isometry3d expected = T_base_imu.inverse() * T_base_cam * T_cam_opt;
  EXPECT_LT((path->T_a_b.matrix() - expected.matrix()).norm(), 1e-12);
  EXPECT_EQ(path->frames, (std::vector<std::string>{"imu", "base_link", "cam", "cam_optical"}));
  EXPECT_EQ(path->sources, (std::vector<std::string>{"/tf_static", "/tf"}));
  const auto back = tree.lookup("cam_optical", "imu");
  ASSERT_TRUE(back);
  EXPECT_LT((back->T_a_b.matrix() - expected.inverse().matrix()).norm(), 1e-12);
  EXPECT_FALSE(tree.lookup("imu", "gps"));
  // A link back to an ancestor would make a loop: refused, the tree unchanged.
  EXPECT_TRUE(tree.add({"cam_optical", "base_link", T_base_cam, "/tf"}));
  EXPECT_TRUE(tree.lookup("imu", "cam_optical"));
}

}  // namespace
}  // namespace gvio::io::ros2
