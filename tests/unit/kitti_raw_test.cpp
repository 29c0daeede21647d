// KITTI raw reader: the fixture drive (extract / sync / simulator layouts) read back field by
// field, the IMU <- camera extrinsic chain checked against an independent computation, and every
// kind of broken input rejected with a message naming the file (and line) at fault.
#include "io/kitti_raw.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include "io/dataset.hpp"
#include "io/input_error.hpp"
#include "support/errors.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;
using test::inputError;
using test::names;
using ::testing::HasSubstr;

// 2011-09-26 13:02:00 UTC, the fixture's first oxts and image_00 stamp.
constexpr std::int64_t kStartNs = (1316995200LL + 13 * 3600 + 2 * 60) * 1'000'000'000LL;

// The what() of the InputError `fn` throws, or "" (with a test failure) when it throws none.

// Removes every line of `file` that starts with `prefix`.
void dropLines(const fs::path& file, const std::string& prefix) {
  std::istringstream in(test::readText(file));
  std::string out, line;
  while (std::getline(in, line)) {
    if (!line.starts_with(prefix)) out += line + "\n";
  }
  test::writeText(file, out);
}

// Line `n` (1-based) of `file`, without its newline.
std::string lineAt(const fs::path& file, std::size_t n) {
  std::istringstream in(test::readText(file));
  std::string line;
  for (std::size_t i = 0; i < n; ++i) std::getline(in, line);
  return line;
}

// The first `n` lines of `file`.
std::string firstLines(const fs::path& file, std::size_t n) {
  std::istringstream in(test::readText(file));
  std::string out, line;
  for (std::size_t i = 0; i < n && std::getline(in, line); ++i) out += line + "\n";
  return out;
}

// Row-major 3x3 rotation and translation as written in the fixture's calib_*.txt.
Eigen::Isometry3d rigid(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

// T_cam0_velo * T_velo_imu from the numbers tests/support/fixtures.cpp writes.
Eigen::Isometry3d cam0FromImu() {
  Eigen::Matrix3d R_velo_imu, R_cam0_velo;
  R_velo_imu << 9.999976e-01, 7.553071e-04, -2.035826e-03, -7.854027e-04, 9.998898e-01,
      -1.482298e-02, 2.024406e-03, 1.482454e-02, 9.998881e-01;
  R_cam0_velo << 7.533745e-03, -9.999714e-01, -6.166020e-04, 1.480249e-02, 7.280733e-04,
      -9.998902e-01, 9.998621e-01, 7.523790e-03, 1.480755e-02;
  const Eigen::Isometry3d T_velo_imu =
      rigid(R_velo_imu, Eigen::Vector3d(-8.086759e-01, 3.195559e-01, -7.997231e-01));
  const Eigen::Isometry3d T_cam0_velo =
      rigid(R_cam0_velo, Eigen::Vector3d(-4.069766e-03, -7.631618e-02, -2.717806e-01));
  return T_cam0_velo * T_velo_imu;
}

class KittiRawTest : public ::testing::Test {
 protected:
  fs::path make(const test::KittiFixture& spec = {}) {
    return test::writeKittiFixture(tmp_.path(), spec);
  }
  static Dataset read(const fs::path& drive, const ReaderConfig& config = {}) {
    return readDataset(drive, DatasetFormat::kKittiRaw, config);
  }
  static std::string errorOf(const fs::path& drive) {
    return inputError([&] { read(drive); });
  }
  [[nodiscard]] fs::path dateDir() const { return tmp_.path() / "2011_09_26"; }

  test::TempDir tmp_{"kitti_raw"};
};

TEST_F(KittiRawTest, ExtractDriveReadsEveryStream) {
  const fs::path drive = make();
  EXPECT_TRUE(looksLikeKittiRaw(drive));
  const Dataset ds = read(drive);
  EXPECT_EQ(ds.format, DatasetFormat::kKittiRaw);
  EXPECT_EQ(ds.variant, "extract");
  EXPECT_EQ(ds.root, drive);
  EXPECT_TRUE(ds.warnings.empty()) << ds.warnings.front();

  ASSERT_EQ(ds.imu.size(), 60U);
  EXPECT_EQ(ds.imu.front().t_ns, kStartNs);
  EXPECT_EQ(ds.imu[1].t_ns - ds.imu[0].t_ns, 10'000'000);
  EXPECT_TRUE(ds.imu[7].acc_b_mps2.isApprox(Eigen::Vector3d(0.1, 0.02, 9.81)));
  EXPECT_TRUE(ds.imu[7].gyr_b_radps.isApprox(Eigen::Vector3d(0.001, -0.002, 0.003)));

  ASSERT_EQ(ds.frames.size(), 6U);
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    EXPECT_EQ(ds.frames[i].t_ns, kStartNs + static_cast<std::int64_t>(i) * 100'000'000);
    ASSERT_EQ(ds.frames[i].image_paths.size(), 2U);
    EXPECT_EQ(ds.frames[i].image_paths[1],
              drive / "image_01" / "data" / ("000000000" + std::to_string(i) + ".png"));
  }
  ASSERT_EQ(ds.cameras.size(), 2U);
  for (const auto& cam : ds.cameras) {
    EXPECT_EQ(cam.width_px, 64);
    EXPECT_EQ(cam.height_px, 24);
    EXPECT_DOUBLE_EQ(cam.fx, 32.0);
    EXPECT_DOUBLE_EQ(cam.cy, 12.0);
    EXPECT_EQ(cam.distortion.size(), 5U);  // extract drives keep the raw, distorted model
  }
  EXPECT_EQ(ds.cameras[0].name, "image_00");
  EXPECT_EQ(ds.cameras[1].name, "image_01");
  EXPECT_NEAR((ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm(), 0.537,
              1e-6);

  ASSERT_EQ(ds.gnss.size(), 60U);
  EXPECT_EQ(ds.gnss_source, (drive / "oxts" / "data").string());
  EXPECT_EQ(ds.gnss.front().t_ns, kStartNs);
  EXPECT_NEAR(ds.gnss.front().lat_deg, 49.011, 1e-9);
  EXPECT_NEAR(ds.gnss.front().lon_deg, 8.4, 1e-9);
  EXPECT_DOUBLE_EQ(ds.gnss.front().h_ellipsoid_m, 116.4);
  EXPECT_DOUBLE_EQ(ds.gnss.front().sigma_h_m, 0.2);
  EXPECT_DOUBLE_EQ(ds.gnss.front().sigma_v_m, 0.2);
  EXPECT_EQ(ds.gnss.front().num_sats, 9);  // field 26 (numsats), not 25 (navstat)
  EXPECT_GT(ds.gnss.back().lat_deg, ds.gnss.front().lat_deg);
  EXPECT_FALSE(ds.groundtruth.has_value());
}

// Largest element-wise difference between T and the general 4x4 inverse of T_c_b. The calibration
// rotations are printed to 7 digits, so they are orthonormal to ~1e-7 only.
double inverseError(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_c_b) {
  const Eigen::Matrix4d expected = T_c_b.matrix().inverse();
  return (T.matrix() - expected).cwiseAbs().maxCoeff();
}

TEST_F(KittiRawTest, CameraExtrinsicsFollowTheCalibrationChain) {
  const Dataset ds = read(make());
  ASSERT_EQ(ds.cameras.size(), 2U);
  EXPECT_LT(inverseError(ds.cameras[0].T_b_c, cam0FromImu()), 1e-6) << ds.cameras[0].T_b_c.matrix();
  // image_01 sits at x = -0.537 m in cam0's frame (R_01 = I, T_01 = [-0.537 0 0]).
  const Eigen::Isometry3d T_c1_c0(Eigen::Translation3d(-0.537, 0.0, 0.0));
  EXPECT_LT(inverseError(ds.cameras[1].T_b_c, T_c1_c0 * cam0FromImu()), 1e-6);
  // The KITTI rig (IMU x forward, y left, z up): cam0 is 1.08 m ahead, 0.31 m right, 0.73 m up.
  EXPECT_TRUE(
      ds.cameras[0].T_b_c.translation().isApprox(Eigen::Vector3d(1.083, -0.310, 0.730), 1e-3))
      << ds.cameras[0].T_b_c.translation().transpose();
}

TEST_F(KittiRawTest, SyncDriveUsesRectifiedCalibrationAndWarnsAboutTenHertzImu) {
  test::KittiFixture spec;
  spec.drive_name = "2011_09_26_drive_0001_sync";
  spec.oxts_rate_hz = 10;
  const Dataset ds = read(make(spec));
  EXPECT_EQ(ds.variant, "sync");
  EXPECT_EQ(ds.imu.size(), 6U);
  EXPECT_EQ(ds.frames.size(), 6U);
  ASSERT_EQ(ds.cameras.size(), 2U);
  EXPECT_TRUE(ds.cameras[0].distortion.empty());
  EXPECT_DOUBLE_EQ(ds.cameras[1].fx, 32.0);
  EXPECT_NEAR((ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm(), 0.537,
              1e-6);
  EXPECT_LT(inverseError(ds.cameras[0].T_b_c, cam0FromImu()), 1e-6);
  ASSERT_EQ(ds.warnings.size(), 1U);
  EXPECT_THAT(ds.warnings[0], HasSubstr("10 Hz"));
  EXPECT_THAT(ds.warnings[0], HasSubstr("oxts"));
}

TEST_F(KittiRawTest, SimulatorDriveNameIsJudgedByOxtsRate) {
  test::KittiFixture spec;
  spec.drive_name = "sim_drive";
  EXPECT_EQ(read(make(spec)).variant, "extract");
  spec.drive_name = "sim_drive_slow";
  spec.oxts_rate_hz = 10;
  EXPECT_EQ(read(make(spec)).variant, "sync");
}

TEST_F(KittiRawTest, CalibrationInsideTheDriveFolder) {
  test::KittiFixture spec;
  spec.calib_in_parent = false;
  const fs::path drive = make(spec);
  EXPECT_FALSE(fs::exists(dateDir() / "calib_cam_to_cam.txt"));
  const Dataset ds = read(drive);
  ASSERT_EQ(ds.cameras.size(), 2U);
  EXPECT_NEAR((ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm(), 0.537,
              1e-6);
}

TEST_F(KittiRawTest, NmeaFixesArePreferredWhenPresent) {
  test::KittiFixture spec;
  spec.frames = 20;  // 2 s of data: two 1 Hz NMEA epochs
  spec.write_nmea = true;
  const fs::path drive = make(spec);
  const Dataset ds = read(drive);
  EXPECT_EQ(ds.gnss_source, (drive / "gnss" / "fixes.nmea").string());
  ASSERT_EQ(ds.gnss.size(), 2U);
  EXPECT_EQ(ds.gnss[0].t_ns, kStartNs);
  EXPECT_EQ(ds.gnss[1].t_ns, kStartNs + 1'000'000'000);
  EXPECT_NEAR(ds.gnss[0].h_ellipsoid_m, 68.4 + 48.0, 1e-9);  // MSL altitude + geoid separation
  EXPECT_NEAR(ds.gnss[0].lat_deg, 49.011, 1e-7);
  EXPECT_NEAR(ds.gnss[0].sigma_h_m, 0.9 * ReaderConfig{}.nmea_uere_spp_m, 1e-9);
  EXPECT_EQ(ds.imu.size(), 200U);  // oxts still gives the IMU
}

TEST_F(KittiRawTest, OxtsGnssSourceOverridesNmea) {
  test::KittiFixture spec;
  spec.write_nmea = true;
  const fs::path drive = make(spec);
  ReaderConfig config;
  config.kitti_gnss_source = "oxts";
  const Dataset ds = read(drive, config);
  EXPECT_EQ(ds.gnss_source, (drive / "oxts" / "data").string());
  EXPECT_EQ(ds.gnss.size(), 60U);
  EXPECT_DOUBLE_EQ(ds.gnss.front().sigma_h_m, 0.2);
}

TEST_F(KittiRawTest, GroundTruthIsLoaded) {
  test::KittiFixture spec;
  spec.write_groundtruth = true;
  const fs::path drive = make(spec);
  const Dataset ds = read(drive);
  ASSERT_TRUE(ds.groundtruth.has_value());
  EXPECT_EQ(ds.groundtruth_source, (drive / "groundtruth.tum").string());
  ASSERT_EQ(ds.groundtruth->size(), 6U);
  ASSERT_TRUE(ds.groundtruth->hasTimestamps());
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(ds.groundtruth->t_ns[i], ds.frames[i].t_ns);
  EXPECT_NEAR(ds.groundtruth->poses[1].translation().x(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(pathLengthM(*ds.groundtruth), 5.0, 1e-5);
}

// ---- bad input ----

TEST_F(KittiRawTest, MissingDriveFolder) {
  const fs::path drive = dateDir() / "2011_09_26_drive_0099_extract";
  EXPECT_TRUE(names(errorOf(drive), drive, 0, "not found"));
}

TEST_F(KittiRawTest, MissingCamToCamCalibration) {
  const fs::path drive = make();
  fs::remove(dateDir() / "calib_cam_to_cam.txt");
  EXPECT_TRUE(names(errorOf(drive), drive / "calib_cam_to_cam.txt", 0, "not found"));
}

TEST_F(KittiRawTest, MissingCalibrationKey) {
  const fs::path drive = make();
  const fs::path c2c = dateDir() / "calib_cam_to_cam.txt";
  dropLines(c2c, "K_01:");
  EXPECT_TRUE(names(errorOf(drive), c2c, 0, "missing key 'K_01'"));

  test::KittiFixture sync;
  sync.drive_name = "2011_09_26_drive_0002_sync";
  sync.oxts_rate_hz = 10;
  const fs::path sync_drive = make(sync);  // rewrites the shared calibration
  dropLines(c2c, "P_rect_01:");
  EXPECT_TRUE(names(errorOf(sync_drive), c2c, 0, "missing key 'P_rect_01'"));
}

TEST_F(KittiRawTest, MalformedCalibrationValue) {
  const fs::path drive = make();
  const fs::path c2c = dateDir() / "calib_cam_to_cam.txt";
  ASSERT_THAT(lineAt(c2c, 4), ::testing::StartsWith("K_00: "));
  test::replaceLine(c2c, 4, "K_00: 32 0 32 0 3x2 12 0 0 1");
  EXPECT_TRUE(names(errorOf(drive), c2c, 4, "malformed value '3x2'"));
  test::replaceLine(c2c, 4, "K_00: 32 0 32 0 32 12 0 0");
  EXPECT_TRUE(names(errorOf(drive), c2c, 4, "K_00 has 8 values, expected 9"));
}

TEST_F(KittiRawTest, OxtsRecordWithTooFewFields) {
  const fs::path drive = make();
  const fs::path rec = drive / "oxts" / "data" / "0000000003.txt";
  std::string text = test::readText(rec);
  text.erase(text.find_last_of(' '));  // drop the last of the 30 values
  test::writeText(rec, text + "\n");
  EXPECT_TRUE(names(errorOf(drive), rec, 1, "expected 30 fields, got 29"));
}

TEST_F(KittiRawTest, OxtsRecordWithNan) {
  const fs::path drive = make();
  const fs::path rec = drive / "oxts" / "data" / "0000000011.txt";
  std::string text = test::readText(rec);
  text.replace(text.find(" 9.81 "), 6, " nan ");
  test::writeText(rec, text);
  EXPECT_TRUE(names(errorOf(drive), rec, 1, "'nan'"));
}

TEST_F(KittiRawTest, OxtsTimestampsNotIncreasing) {
  const fs::path drive = make();
  const fs::path stamps = drive / "oxts" / "timestamps.txt";
  test::replaceLine(stamps, 5, lineAt(stamps, 2));
  EXPECT_TRUE(names(errorOf(drive), stamps, 5, "timestamp not increasing"));
}

TEST_F(KittiRawTest, DuplicateCameraTimestamp) {
  const fs::path drive = make();
  const fs::path stamps = drive / "image_00" / "timestamps.txt";
  test::replaceLine(stamps, 4, lineAt(stamps, 3));
  EXPECT_TRUE(names(errorOf(drive), stamps, 4, "duplicate timestamp"));
}

TEST_F(KittiRawTest, SecondCameraHasFewerTimestamps) {
  const fs::path drive = make();
  const fs::path stamps = drive / "image_01" / "timestamps.txt";
  test::writeText(stamps, firstLines(stamps, 5));
  EXPECT_TRUE(names(errorOf(drive), stamps, 0, "5 timestamps, but image_00 has 6"));
}

TEST_F(KittiRawTest, MissingImageFile) {
  const fs::path drive = make();
  const fs::path image = drive / "image_01" / "data" / "0000000002.png";
  fs::remove(image);
  EXPECT_TRUE(names(errorOf(drive), image, 0, "image file not found"));
}

TEST_F(KittiRawTest, MissingOxtsRecord) {
  const fs::path drive = make();
  const fs::path rec = drive / "oxts" / "data" / "0000000042.txt";
  fs::remove(rec);
  EXPECT_TRUE(names(errorOf(drive), rec, 0, "file not found"));
}

TEST_F(KittiRawTest, EmptyTimestampsFile) {
  const fs::path drive = make();
  const fs::path stamps = drive / "image_00" / "timestamps.txt";
  test::writeText(stamps, "");
  EXPECT_TRUE(names(errorOf(drive), stamps, 0, "no timestamps"));
  test::writeText(stamps, "\n");
  EXPECT_TRUE(names(errorOf(drive), stamps, 1, "empty line"));
}

}  // namespace
}  // namespace gvio::io
