// Fuzz targets for ROS 2 bags (issue 60): an MCAP file (uncompressed and zstd chunks), an sqlite3
// .db3, a bag folder's metadata.yaml, each read as `gvio run` opens the bag (calibration from its
// CameraInfo and /tf_static), and single CDR messages of every type gvio decodes.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fuzz/checks.hpp"
#include "fuzz/harness.hpp"
#include "fuzz/targets_list.hpp"
#include "io/dataset.hpp"
#include "io/kalibr_writer.hpp"
#include "io/ros2/ros2_bag_writer.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros_image.hpp"
#include "odometry/error.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {
namespace {
namespace fs = std::filesystem;
namespace ros2 = io::ros2;

ros2::TransformMessage link(const std::string& child, double x, double y) {
  ros2::TransformMessage m;
  m.frame_id = "imu";
  m.child_frame_id = child;
  m.translation = {x, y, 0.0};
  // Camera frames (z forward) in an IMU frame with x forward: a fixed rotation.
  m.rotation_xyzw = {-0.5, 0.5, -0.5, 0.5};
  return m;
}

// A stereo 32x16 drive as `gvio simulate --format ros2bag` writes one: images, CameraInfo, IMU,
// a fix and /tf_static, in `folder`.
void writeSmallBag(const fs::path& folder, ros2::Ros2Storage storage,
                   const std::string& compression) {
  fs::create_directories(folder);
  for (const auto& entry : fs::directory_iterator(folder)) fs::remove(entry.path());
  ros2::Ros2BagWriter w(folder, "drive", storage, compression);
  std::size_t images[2], infos[2];
  for (int c = 0; c < 2; ++c) {
    images[c] = w.addTopic(fmt::format("/cam{}/image_raw", c), ros2::kRos2ImageType);
    infos[c] = w.addTopic(fmt::format("/cam{}/camera_info", c), ros2::kRos2CameraInfoType);
  }
  const std::size_t imu = w.addTopic("/imu0", ros2::kRos2ImuType);
  const std::size_t gnss = w.addTopic("/gnss/fix", ros2::kRos2NavSatFixType);
  const std::size_t tf = w.addTopic("/tf_static", ros2::kRos2TfType);
  const std::int64_t t0 = 1'600'000'000'000'000'000;
  const std::vector<ros2::TransformMessage> links = {link("cam0", 0.0, 0.0),
                                                     link("cam1", 0.0, -0.5), link("gnss", 0, 0)};
  w.write(tf, t0, ros2::encodeTfMessage(links));
  for (int i = 0; i < 12; ++i) {
    ros2::Ros2Imu m;
    m.imu.t.header_ns = t0 + i * 10'000'000LL;
    m.imu.acc_mps2 = {0.1, 0.2, 9.81};
    m.imu.gyr_radps = {0.01, -0.02, 0.03};
    m.frame_id = "imu";
    w.write(imu, m.imu.t.header_ns, ros2::encodeImu(m));
    if (i % 5 != 0) continue;
    const int frame = i / 5;
    for (int c = 0; c < 2; ++c) {
      ros2::Ros2Image image;
      image.image =
          io::grayToRosImage(cv::Mat(16, 32, CV_8UC1, cv::Scalar(60 + 40 * c + frame)), false);
      image.image.t.header_ns = m.imu.t.header_ns;
      image.frame_id = fmt::format("cam{}", c);
      w.write(images[c], m.imu.t.header_ns, ros2::encodeImage(image));
      ros2::CameraInfoMessage info;
      info.t.header_ns = m.imu.t.header_ns;
      info.frame_id = image.frame_id;
      info.width = 32;
      info.height = 16;
      info.distortion_model = "plumb_bob";
      info.d = {0.01, -0.002, 0.0001, 0.0002, 0.0};
      info.k = {20.0, 0.0, 16.0, 0.0, 21.0, 8.0, 0.0, 0.0, 1.0};
      info.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      info.p = {20.0, 0.0, 16.0, c == 1 ? -10.0 : 0.0, 0.0, 21.0, 8.0, 0.0, 0.0, 0.0, 1.0, 0.0};
      w.write(infos[c], m.imu.t.header_ns, ros2::encodeCameraInfo(info));
    }
  }
  ros2::Ros2NavSatFix fix;
  fix.fix.t.header_ns = t0;
  fix.fix.status = 0;
  fix.fix.lat_deg = 48.1;
  fix.fix.lon_deg = 11.5;
  fix.fix.alt_m = 500.0;
  fix.fix.covariance_enu_m2 = {1.0, 0, 0, 0, 1.0, 0, 0, 0, 4.0};
  fix.fix.covariance_type = 2;
  fix.frame_id = "gnss";
  w.write(gnss, t0, ros2::encodeNavSatFix(fix));
  w.close();
}

void prepareBags(const fs::path& dir) {
  writeSmallBag(dir / "bag", ros2::Ros2Storage::kMcap, "none");
  writeSmallBag(dir / "zstd", ros2::Ros2Storage::kMcap, "zstd");
  writeSmallBag(dir / "sqlite", ros2::Ros2Storage::kSqlite3, "none");
  test::writeText(dir / "imu.yaml", io::kalibrImuYaml(ImuNoise{}, 100.0, "/imu0"));
}

Target bagTarget(std::string name, const std::string& folder, const std::string& file,
                 bool whole_folder) {
  return Target{std::move(name), folder + "/" + file, prepareBags,
                [=](const fs::path& d) {
                  readWholeDataset(whole_folder ? d / folder : d / folder / file, {d / "imu.yaml"});
                },
                ""};
}

// One CDR message: byte 0 picks the type, the rest is the message. What decodes must encode
// and decode to the same values.
void readCdr(const fs::path& d) {
  std::ifstream in(d / "message.cdr", std::ios::binary);
  const std::vector<std::uint8_t> b((std::istreambuf_iterator<char>(in)), {});
  if (b.empty()) return;
  const std::span<const std::uint8_t> m(b.data() + 1, b.size() - 1);
  try {
    switch (b[0] % 6) {
      case 0: {
        const ros2::Ros2Imu x = ros2::decodeImu(m);
        require(ros2::encodeImu(ros2::decodeImu(ros2::encodeImu(x))) == ros2::encodeImu(x),
                "Imu does not survive a round trip");
        break;
      }
      case 1:
        (void)ros2::encodeNavSatFix(ros2::decodeNavSatFix(m));
        break;
      case 2:
        (void)io::rosImageToGray(ros2::decodeImage(m).image);
        break;
      case 3:
        (void)io::rosImageToGray(ros2::decodeCompressedImage(m).image);
        break;
      case 4:
        (void)ros2::encodeCameraInfo(ros2::decodeCameraInfo(m));
        break;
      default:
        (void)ros2::encodeTfMessage(ros2::decodeTfMessage(m));
    }
  } catch (const io::bag::BagError& e) {
    throw gvio::InvalidInput(e.what());
  }
}

void prepareCdr(const fs::path& dir) {
  ros2::Ros2Imu m;
  m.imu.t.header_ns = 1'600'000'000'123'456'789;
  m.imu.acc_mps2 = {0.1, 0.2, 9.81};
  m.frame_id = "imu_link";
  const std::vector<std::uint8_t> bytes = ros2::encodeImu(m);
  std::string file(1, '\0');
  file.append(bytes.begin(), bytes.end());
  test::writeText(dir / "message.cdr", file);
}

}  // namespace

void addRos2Targets(std::vector<Target>& out) {
  out.push_back(bagTarget("ros2_mcap", "bag", "drive_0.mcap", false));
  out.push_back(bagTarget("ros2_mcap_zstd", "zstd", "drive_0.mcap", false));
  out.push_back(bagTarget("ros2_db3", "sqlite", "drive_0.db3", false));
  out.push_back(bagTarget("ros2_metadata", "bag", "metadata.yaml", true));
  out.push_back(Target{"ros2_cdr", "message.cdr", prepareCdr, readCdr, "-"});
}

}  // namespace gvio::fuzz
