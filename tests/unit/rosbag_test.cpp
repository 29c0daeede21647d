// ROS1 bags (issue 16): topics chosen by type or named, every stream in header-stamp order with
// repairs counted, stereo pairing, NavSatFix sigmas and quality, all three chunk compressions, and
// one-line errors naming the bag for broken or unusable bags.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>

#include "io/dataset.hpp"
#include "io/input_error.hpp"
#include "io/ros_image.hpp"
#include "io/rosbag/bag_file.hpp"
#include "io/rosbag_dataset.hpp"
#include "support/errors.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

constexpr std::int64_t kT0 = 1'600'000'000'000'000'000;
constexpr std::int64_t kFrameNs = 100'000'000;

cv::Mat pattern(int frame) {
  cv::Mat image(24, 32, CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c)
      image.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(r * 7 + c * 3 + frame);
  }
  return image;
}

bag::ImageMessage image(std::int64_t t_ns, int frame) {
  bag::ImageMessage m = grayToRosImage(pattern(frame), false);
  m.t = {t_ns, t_ns};
  return m;
}

bag::ImuMessage imu(std::int64_t t_ns, double ax) {
  bag::ImuMessage m;
  m.t = {t_ns, t_ns};
  m.acc_mps2 = {ax, 0.0, 9.81};
  m.gyr_radps = {0.0, 0.0, 0.01};
  return m;
}

bag::NavSatFixMessage fix(std::int64_t t_ns, int status, double sigma_h_m, int covariance_type) {
  bag::NavSatFixMessage m;
  m.t = {t_ns, t_ns};
  m.status = status;
  m.lat_deg = 48.98;
  m.lon_deg = 8.39;
  m.alt_m = 116.0;
  m.covariance_enu_m2 = {sigma_h_m * sigma_h_m,    0, 0, 0, sigma_h_m * sigma_h_m, 0, 0, 0,
                         4 * sigma_h_m * sigma_h_m};
  m.covariance_type = covariance_type;
  return m;
}

fs::path writeBag(const fs::path& file, bag::Compression compression,
                  const std::function<void(bag::BagWriter&)>& fill) {
  bag::BagWriter writer(file.string(), compression);
  fill(writer);
  writer.close();
  return file;
}

// A stereo drive of 5 frames on /cam0 and /cam1, 100 Hz IMU and 1 Hz fixes.
void stereoDrive(bag::BagWriter& w) {
  for (int k = 0; k < 5; ++k) {
    w.write("/cam0/image_raw", image(kT0 + k * kFrameNs, k));
    w.write("/cam1/image_raw", image(kT0 + k * kFrameNs, 100 + k));
  }
  for (int i = 0; i < 50; ++i) w.write("/imu0", imu(kT0 + i * 10'000'000, 0.1 * i));
  w.write("/gnss/fix", fix(kT0, 0, 2.0, 2));
}

TEST(Rosbag, StereoDriveInEveryCompression) {
  test::TempDir dir("rosbag");
  for (const auto compression :
       {bag::Compression::kNone, bag::Compression::kBz2, bag::Compression::kLz4}) {
    const fs::path file =
        writeBag(dir.path() / fmt::format("c{}.bag", static_cast<int>(compression)), compression,
                 stereoDrive);
    EXPECT_TRUE(looksLikeRosbag(file));
    EXPECT_EQ(detectFormat(file), DatasetFormat::kRosbag);
    const Dataset ds = readDataset(file, std::nullopt, ReaderConfig{});
    EXPECT_EQ(ds.format, DatasetFormat::kRosbag);
    ASSERT_EQ(ds.cameras.size(), 2U);
    EXPECT_EQ(ds.cameras[0].width_px, 32);
    EXPECT_EQ(ds.cameras[0].height_px, 24);
    EXPECT_EQ(ds.cameras[0].fx, 0.0);  // uncalibrated: --calib supplies intrinsics
    ASSERT_EQ(ds.frames.size(), 5U);
    EXPECT_EQ(ds.frames[3].t_ns, kT0 + 3 * kFrameNs);
    ASSERT_EQ(ds.imu.size(), 50U);
    EXPECT_DOUBLE_EQ(ds.imu[7].acc_b_mps2.x(), 0.7);
    ASSERT_EQ(ds.gnss.size(), 1U);
    // Frame 2's images: cam0 and cam1 differ, and each is the pixel pattern written.
    const cv::Mat left = loadFrameImage(ds, 2, 0), right = loadFrameImage(ds, 2, 1);
    EXPECT_EQ(cv::norm(left, pattern(2), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(right, pattern(102), cv::NORM_INF), 0.0);
    EXPECT_EQ(imageSource(ds, 2, 1), file.string() + ":/cam1/image_raw");
    ASSERT_EQ(ds.bag_topics.size(), 4U);
    EXPECT_EQ(ds.bag_topics[0].role, "cam0");
    EXPECT_EQ(ds.bag_topics[2].topic, "/imu0");
    EXPECT_EQ(ds.bag_topics[2].used, 50U);
  }
}

TEST(Rosbag, OutOfOrderAndRepeatedStampsAreSortedDroppedAndCounted) {
  test::TempDir dir("rosbag");
  const fs::path file = writeBag(dir.path() / "order.bag", bag::Compression::kNone, [](auto& w) {
    // Header stamps 0, 2, 1, 3, 3 (receive times increasing): one out of order, one repeat.
    const int order[] = {0, 2, 1, 3, 3};
    for (int i = 0; i < 5; ++i) {
      bag::ImuMessage m = imu(kT0 + order[i] * 10'000'000, order[i]);
      m.t.receive_ns = kT0 + i * 10'000'000 + 5'000'000;
      w.write("/imu", m);
    }
    bag::ImageMessage zero = image(0, 1);  // a driver that leaves header.stamp unset
    zero.t.receive_ns = kT0 + kFrameNs;
    w.write("/cam", image(kT0, 0));
    w.write("/cam", zero);
  });
  const Dataset ds = readDataset(file, DatasetFormat::kRosbag, ReaderConfig{});
  ASSERT_EQ(ds.imu.size(), 4U);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(ds.imu[i].t_ns, kT0 + static_cast<std::int64_t>(i) * 10'000'000);
    EXPECT_DOUBLE_EQ(ds.imu[i].acc_b_mps2.x(), static_cast<double>(i));
  }
  ASSERT_EQ(ds.frames.size(), 2U);
  EXPECT_EQ(ds.frames[1].t_ns, kT0 + kFrameNs);
  const BagTopicUse& cam = ds.bag_topics[0];
  const BagTopicUse& imu_use = ds.bag_topics[1];
  EXPECT_EQ(cam.zero_stamps, 1U);
  EXPECT_EQ(imu_use.out_of_order, 1U);
  EXPECT_EQ(imu_use.duplicate_stamps, 1U);
  EXPECT_EQ(imu_use.messages, 5U);
  EXPECT_EQ(imu_use.used, 4U);
  EXPECT_THAT(ds.warnings.back(), HasSubstr("1 messages out of order"));
}

TEST(Rosbag, StereoPairsWithinTheSyncToleranceOnly) {
  test::TempDir dir("rosbag");
  const fs::path file = writeBag(dir.path() / "sync.bag", bag::Compression::kNone, [](auto& w) {
    for (int k = 0; k < 4; ++k) {
      w.write("/left/image", image(kT0 + k * kFrameNs, k));
      // The right camera 1 ms late, except frame 2, 20 ms late.
      w.write("/right/image", image(kT0 + k * kFrameNs + (k == 2 ? 20'000'000 : 1'000'000), k));
    }
  });
  const Dataset ds = readDataset(file, std::nullopt, ReaderConfig{});
  ASSERT_EQ(ds.frames.size(), 3U);
  EXPECT_EQ(ds.frames[2].t_ns, kT0 + 3 * kFrameNs);
  EXPECT_EQ(ds.bag_topics[0].topic, "/left/image");
  EXPECT_THAT(ds.warnings.front(), HasSubstr("1 of 4 images on /left/image have no image"));
  ReaderConfig loose;
  loose.stereo_sync_tolerance_s = 0.025;
  EXPECT_EQ(readDataset(file, std::nullopt, loose).frames.size(), 4U);
}

TEST(Rosbag, TopicsNamedInConfigOrRefusedWhenAmbiguous) {
  test::TempDir dir("rosbag");
  const fs::path file = writeBag(dir.path() / "many.bag", bag::Compression::kNone, [](auto& w) {
    for (int k = 0; k < 3; ++k) {
      w.write("/camera/image_raw", image(kT0 + k * kFrameNs, k));
      w.write("/camera/image_rect", image(kT0 + k * kFrameNs, 50 + k));
      w.write("/imu_a", imu(kT0 + k * kFrameNs, 1.0));
      w.write("/imu_b", imu(kT0 + k * kFrameNs, 2.0));
    }
  });
  ReaderConfig config;
  config.topic_imu = "/imu_b";
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(file, std::nullopt, config); }),
                          file, 0, "are not one camera or a left/right pair"));
  config.topic_cam0 = "/camera/image_rect";
  const Dataset ds = readDataset(file, std::nullopt, config);
  ASSERT_EQ(ds.cameras.size(), 1U);
  EXPECT_EQ(cv::norm(loadFrameImage(ds, 1, 0), pattern(51), cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(ds.imu.front().acc_b_mps2.x(), 2.0);
  config.topic_imu.clear();
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(file, std::nullopt, config); }),
                          file, 0,
                          "2 IMU topics (/imu_a, /imu_b): name one with --set dataset.topics.imu"));
  config.topic_imu = "/camera/image_raw";
  EXPECT_TRUE(
      test::names(test::inputError([&] { (void)readDataset(file, std::nullopt, config); }), file, 0,
                  "topic /camera/image_raw is sensor_msgs/Image, expected sensor_msgs/Imu"));
  config.topic_imu = "/nothing";
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(file, std::nullopt, config); }),
                          file, 0, "no topic /nothing in the bag"));
}

TEST(Rosbag, NavSatFixStatusAndCovarianceToQualityAndSigmas) {
  test::TempDir dir("rosbag");
  const fs::path file = writeBag(dir.path() / "gnss.bag", bag::Compression::kNone, [](auto& w) {
    w.write("/fix", fix(kT0, -1, 1.0, 2));                  // no fix: skipped
    w.write("/fix", fix(kT0 + 1'000'000'000, 0, 2.5, 2));   // SPP with a stated sigma
    w.write("/fix", fix(kT0 + 2'000'000'000, 0, 2.5, 0));   // covariance unknown
    w.write("/fix", fix(kT0 + 3'000'000'000, 2, 0.02, 3));  // GBAS, centimetre: RTK fixed
    w.write("/fix", fix(kT0 + 4'000'000'000, 2, 0.4, 3));   // GBAS, decimetre: RTK float
    auto sbas = fix(kT0 + 5'000'000'000, 1, 0.8, 1);  // SBAS: approximated, no correlation read
    sbas.covariance_enu_m2[1] = sbas.covariance_enu_m2[3] = 0.3;
    w.write("/fix", sbas);
    auto off_globe = fix(kT0 + 6'000'000'000, 0, 2.5, 2);  // longitude 200 deg: skipped
    off_globe.lon_deg = 200.0;
    w.write("/fix", off_globe);
    auto below_pole = fix(kT0 + 7'000'000'000, 0, 2.5, 2);  // latitude -91 deg: skipped
    below_pole.lat_deg = -91.0;
    w.write("/fix", below_pole);
  });
  ReaderConfig config;
  const Dataset ds = readDataset(file, std::nullopt, config);
  ASSERT_EQ(ds.gnss.size(), 5U);
  EXPECT_EQ(ds.gnss[0].quality, 1);
  EXPECT_DOUBLE_EQ(ds.gnss[0].sigma_h_m, 2.5);
  EXPECT_DOUBLE_EQ(ds.gnss[0].sigma_v_m, 5.0);
  EXPECT_DOUBLE_EQ(ds.gnss[1].sigma_h_m, config.nmea_uere_spp_m);
  EXPECT_DOUBLE_EQ(ds.gnss[1].sigma_v_m, config.nmea_uere_spp_m * config.nmea_vertical_factor);
  EXPECT_EQ(ds.gnss[2].quality, 4);
  EXPECT_DOUBLE_EQ(ds.gnss[2].sigma_h_m, 0.02);
  EXPECT_EQ(ds.gnss[3].quality, 5);
  EXPECT_EQ(ds.gnss[4].quality, 2);
  EXPECT_EQ(ds.gnss[4].shape_en, Eigen::Matrix2d::Identity());
  EXPECT_DOUBLE_EQ(ds.gnss[0].h_ellipsoid_m, 116.0);
  EXPECT_EQ(ds.gnss_source, file.string() + ":/fix");
  EXPECT_THAT(ds.warnings.front(), HasSubstr("3 messages without a fix skipped"));
}

// A NavSatFix whose covariance is known in full (type 3) states its east-north correlation: the
// fix's ellipse.
TEST(Rosbag, AKnownCovarianceGivesTheEllipse) {
  test::TempDir dir("rosbag");
  const fs::path file = writeBag(dir.path() / "gnss.bag", bag::Compression::kNone, [](auto& w) {
    auto known = fix(kT0, 0, 2.0, 3);
    known.covariance_enu_m2[0] = 9.0;                                // east 3 m
    known.covariance_enu_m2[1] = known.covariance_enu_m2[3] = -1.2;  // rho -0.4
    w.write("/fix", known);
  });
  const Dataset ds = readDataset(file, std::nullopt, ReaderConfig{});
  ASSERT_EQ(ds.gnss.size(), 1U);
  Eigen::Matrix2d cov;
  cov << 9.0, -1.2, -1.2, 4.0;
  EXPECT_LT((ds.gnss[0].shape_en - 2.0 * cov / cov.trace()).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(ds.gnss[0].sigma_h_m, std::sqrt(6.5));
}

TEST(Rosbag, BrokenBagsAreOneLineErrorsNamingTheBag) {
  test::TempDir dir("rosbag");
  const fs::path good = writeBag(dir.path() / "good.bag", bag::Compression::kLz4, stereoDrive);
  std::string bytes = test::readText(good);

  const fs::path truncated = dir.path() / "truncated.bag";
  test::writeText(truncated, bytes.substr(0, bytes.size() / 2));
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(truncated, std::nullopt, {}); }),
                          truncated, 0, ""));

  // An interrupted recording: the header's index position still zero (rosbag writes it on close).
  const fs::path unindexed = dir.path() / "unindexed.bag";
  {
    bag::BagWriter writer(unindexed.string(), bag::Compression::kNone);
    writer.write("/imu0", imu(kT0, 0.0));
    std::error_code ec;
    fs::copy_file(unindexed, dir.path() / "open.bag", ec);  // copied before close: no index yet
    ASSERT_FALSE(ec) << ec.message();
  }
  const fs::path open = dir.path() / "open.bag";
  const std::string open_error =
      test::inputError([&] { (void)readDataset(open, std::nullopt, {}); });
  EXPECT_TRUE(test::names(open_error, open, 0, "")) << open_error;
  EXPECT_THAT(open_error,
              testing::AnyOf(HasSubstr("unindexed"), HasSubstr("reindex"), HasSubstr("index")));

  const fs::path not_bag = dir.path() / "text.bag";
  test::writeText(not_bag, "hello\n");
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(not_bag, std::nullopt, {}); }),
                          not_bag, 0, "not a ROS bag"));

  const fs::path yuv = writeBag(dir.path() / "yuv.bag", bag::Compression::kNone, [](auto& w) {
    bag::ImageMessage m = image(kT0, 0);
    m.encoding = "yuv422";
    w.write("/cam", m);
  });
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(yuv, std::nullopt, {}); }), yuv,
                          0, "topic /cam: image 0: image encoding 'yuv422' is not supported"));
}

// librosbag reads the version line with fgets and the file header from where the stream then
// stands, after the newline, while the version it scans ends at the first NUL: the check walks the
// records from that same byte. Here the bytes up to the newline pass for one empty record when
// walked from the NUL, and the length after the newline asks for 1.9 GB (a fuzz finding).
TEST(Rosbag, TheFileHeaderIsCheckedWhereLibrosbagReadsIt) {
  test::TempDir dir("rosbag");
  const fs::path file = dir.path() / "nul.bag";
  std::string bytes = std::string("#ROSBAG V2.0") + std::string(4, '\0');  // empty header at 12
  bytes += std::string("\x10\0\0\0", 4);                                   // 16 bytes of data
  bytes += "\n" + std::string("\x45\x3c\x2f\x70", 4) + std::string(11, ' ');
  test::writeText(file, bytes);
  EXPECT_TRUE(test::names(test::inputError([&] { (void)readDataset(file, std::nullopt, {}); }),
                          file, 0, "record at byte 21: header runs past the end"));
}

// ROS's deserialiser sizes a uint8[] from the length the message states before it reads the bytes:
// an image stating 1 GB in a small bag was 1 GB allocated and zeroed (a fuzz finding). The stated
// length is now checked against the message first, raw and PNG alike.
TEST(Rosbag, ImageDataLongerThanItsMessageIsRefusedBeforeItIsAllocated) {
  test::TempDir dir("rosbag");
  for (const bool png : {false, true}) {
    const fs::path file =
        writeBag(dir.path() / (png ? "png.bag" : "raw.bag"), bag::Compression::kNone, [&](auto& w) {
          bag::ImageMessage m = grayToRosImage(pattern(0), png);
          m.t = {kT0, kT0};
          w.write("/cam", m);
        });
    std::string bytes = test::readText(file);
    // The data's length: before the PNG signature, or after the encoding, is_bigendian and step.
    const std::string before = png ? std::string("\x89PNG") : std::string("\x05\0\0\0mono8", 9);
    const std::size_t at = bytes.find(before);
    ASSERT_NE(at, std::string::npos);
    ASSERT_EQ(bytes.find(before, at + 1), std::string::npos);
    const std::size_t length_at = png ? at - 4 : at + before.size() + 5;
    bytes.replace(length_at, 4, std::string("\0\0\0\x3c", 4));  // 1006632960 bytes
    test::writeText(file, bytes);
    const std::string error = test::inputError([&] { (void)readDataset(file, std::nullopt, {}); });
    EXPECT_TRUE(
        test::names(error, file, 0, "image data of 1006632960 bytes stated in a message of"))
        << error;
  }
}

}  // namespace
}  // namespace gvio::io
