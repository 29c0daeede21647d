// EuRoC / ASL reader: the real V1_01 clip (when the shared data is present) and small synthetic
// mav0 folders written here, valid and broken.
#include "io/euroc.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <filesystem>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "support/errors.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;
using test::inputError;
using test::names;
using ::testing::HasSubstr;

constexpr std::int64_t kT0 = 1'403'715'273'262'142'976;  // the V1_01 clip's first IMU stamp

// ---- the real clip ----

TEST(EurocRealClip, ReadsV101Micro) {
  const fs::path root = test::sharedData("euroc_v101_micro");
  if (root.empty()) GTEST_SKIP() << "shared data absent: euroc_v101_micro";
  const Dataset ds = readDataset(root, std::nullopt, ReaderConfig{});
  EXPECT_EQ(ds.format, DatasetFormat::kEuroc);
  EXPECT_EQ(ds.variant, "asl");

  ASSERT_EQ(ds.cameras.size(), 2U);
  for (const auto& cam : ds.cameras) {
    EXPECT_EQ(cam.width_px, 752);
    EXPECT_EQ(cam.height_px, 480);
    EXPECT_EQ(cam.distortion.size(), 4U);
  }
  EXPECT_DOUBLE_EQ(ds.cameras[0].fx, 458.654);
  EXPECT_EQ(ds.cameras[0].name, "cam0");
  EXPECT_NEAR((ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm(), 0.110,
              0.001);  // the VI-sensor's 11 cm stereo baseline

  ASSERT_EQ(ds.frames.size(), 95U);
  for (const auto& f : ds.frames) ASSERT_EQ(f.image_paths.size(), 2U);
  const double span_s = 1e-9 * static_cast<double>(ds.frames.back().t_ns - ds.frames[0].t_ns);
  EXPECT_NEAR(span_s / 94.0, 0.05, 1e-3);  // 20 Hz

  ASSERT_EQ(ds.imu.size(), 29120U);
  EXPECT_EQ(ds.imu[0].t_ns, kT0);
  EXPECT_DOUBLE_EQ(ds.imu[0].gyr_b_radps.x(), -0.0020943951023931952);
  EXPECT_DOUBLE_EQ(ds.imu[0].gyr_b_radps.z(), 0.07749261878854824);
  EXPECT_DOUBLE_EQ(ds.imu[0].acc_b_mps2.x(), 9.0874956666666655);
  EXPECT_DOUBLE_EQ(ds.imu[0].acc_b_mps2.z(), -3.6938381666666662);
  ASSERT_TRUE(ds.imu_noise.has_value());
  EXPECT_DOUBLE_EQ(ds.imu_noise->gyr_noise_density, 1.6968e-04);
  EXPECT_DOUBLE_EQ(ds.imu_noise->gyr_random_walk, 1.9393e-05);
  EXPECT_DOUBLE_EQ(ds.imu_noise->acc_noise_density, 2.0e-3);
  EXPECT_DOUBLE_EQ(ds.imu_noise->acc_random_walk, 3.0e-3);
  EXPECT_TRUE(ds.gnss.empty());

  ASSERT_EQ(ds.warnings.size(), 1U);
  EXPECT_THAT(ds.warnings[0], HasSubstr("cam1/data.csv"));
  EXPECT_THAT(ds.warnings[0], HasSubstr("4"));

  for (std::size_t c = 0; c < 2; ++c) {
    const cv::Mat image = loadGrayImage(ds.frames[0].image_paths[c], ds.cameras[c]);
    EXPECT_EQ(image.cols, 752);
    EXPECT_EQ(image.rows, 480);
    EXPECT_EQ(image.type(), CV_8UC1);
  }
}

// ---- synthetic folders ----

constexpr std::int64_t kImuPeriodNs = 5'000'000;  // 200 Hz

class EurocTest : public ::testing::Test {
 protected:
  [[nodiscard]] fs::path mav0() const { return tmp_.path() / "mav0"; }

  // imu0/sensor.yaml (Kalibr style) and `rows` samples at 200 Hz.
  void writeImu(int rows) const {
    test::writeText(mav0() / "imu0" / "sensor.yaml",
                    "%YAML:1.0\nsensor_type: imu\nrate_hz: 200\n"
                    "gyroscope_noise_density: 1.5e-04\ngyroscope_random_walk: 2.0e-05\n"
                    "accelerometer_noise_density: 2.5e-3\naccelerometer_random_walk: 3.5e-3\n");
    std::string csv = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";
    for (int i = 0; i < rows; ++i) {
      csv += fmt::format("{},0.01,-0.02,0.03,0.1,0.2,9.81\n", kT0 + i * kImuPeriodNs);
    }
    test::writeText(imuCsv(), csv);
  }
  [[nodiscard]] fs::path imuCsv() const { return mav0() / "imu0" / "data.csv"; }

  // gnss0/data.csv: one row per entry of `rows` ("lat,lon,h,sigma_h,sigma_v"), 1 s apart.
  void writeGnss(const std::vector<std::string>& rows) const {
    std::string csv = "#timestamp [ns],lat [deg],lon [deg],h [m],sigma_h [m],sigma_v [m]\n";
    for (std::size_t i = 0; i < rows.size(); ++i) {
      csv += fmt::format("{},{}\n", kT0 + static_cast<std::int64_t>(i) * 1'000'000'000, rows[i]);
    }
    test::writeText(mav0() / "gnss0" / "data.csv", csv);
  }

  // camN/sensor.yaml (32x16 pinhole) and `frames` 32x16 PNGs at 20 Hz.
  void writeCamera(const std::string& name, int frames) const {
    const fs::path dir = mav0() / name;
    test::writeText(dir / "sensor.yaml",
                    "%YAML:1.0\nsensor_type: camera\nrate_hz: 20\nresolution: [32, 16]\n"
                    "camera_model: pinhole\nintrinsics: [20.0, 21.0, 16.0, 8.0]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n");
    std::string csv = "#timestamp [ns],filename\n";
    fs::create_directories(dir / "data");
    for (int i = 0; i < frames; ++i) {
      const std::int64_t t = kT0 + i * 10 * kImuPeriodNs;
      csv += fmt::format("{},{}.png\n", t, t);
      cv::imwrite(imagePath(name, i).string(), cv::Mat(16, 32, CV_8UC1, cv::Scalar(40 + i)));
    }
    test::writeText(dir / "data.csv", csv);
  }
  [[nodiscard]] fs::path imagePath(const std::string& name, int frame) const {
    return mav0() / name / "data" / fmt::format("{}.png", kT0 + frame * 10 * kImuPeriodNs);
  }

  [[nodiscard]] Dataset read() const {
    return readDataset(tmp_.path(), std::nullopt, ReaderConfig{});
  }
  [[nodiscard]] std::string error() const {
    return inputError([this] { (void)read(); });
  }

  test::TempDir tmp_{"euroc"};
};

TEST_F(EurocTest, ImuAndGnssWithoutCamerasIsValid) {
  writeImu(50);
  writeGnss({"47.3667,8.55,500.0,1.5,3.0", "47.3668,8.5501,500.5,1.2,2.5"});
  const Dataset ds = read();
  EXPECT_EQ(ds.format, DatasetFormat::kEuroc);
  EXPECT_TRUE(ds.cameras.empty());
  EXPECT_TRUE(ds.frames.empty());
  EXPECT_TRUE(ds.warnings.empty());
  ASSERT_EQ(ds.imu.size(), 50U);
  EXPECT_EQ(ds.imu[49].t_ns, kT0 + 49 * kImuPeriodNs);
  EXPECT_TRUE(ds.imu[3].acc_b_mps2.isApprox(Eigen::Vector3d(0.1, 0.2, 9.81)));
  ASSERT_TRUE(ds.imu_noise.has_value());
  EXPECT_DOUBLE_EQ(ds.imu_noise->acc_random_walk, 3.5e-3);
  ASSERT_EQ(ds.gnss.size(), 2U);
  EXPECT_EQ(ds.gnss_source, (mav0() / "gnss0" / "data.csv").string());
  EXPECT_EQ(ds.gnss[1].t_ns, kT0 + 1'000'000'000);
  EXPECT_DOUBLE_EQ(ds.gnss[0].lat_deg, 47.3667);
  EXPECT_DOUBLE_EQ(ds.gnss[1].h_ellipsoid_m, 500.5);
  EXPECT_DOUBLE_EQ(ds.gnss[0].sigma_h_m, 1.5);
  EXPECT_DOUBLE_EQ(ds.gnss[0].sigma_v_m, 3.0);
  EXPECT_DOUBLE_EQ(ds.gnss[1].sigma_h_m, 1.2);
}

TEST_F(EurocTest, StereoFramesPairByStamp) {
  writeImu(100);
  writeCamera("cam0", 4);
  writeCamera("cam1", 4);
  const Dataset ds = read();
  ASSERT_EQ(ds.cameras.size(), 2U);
  EXPECT_DOUBLE_EQ(ds.cameras[1].fy, 21.0);
  ASSERT_EQ(ds.frames.size(), 4U);
  EXPECT_EQ(ds.frames[2].image_paths[1], imagePath("cam1", 2));
  EXPECT_EQ(loadGrayImage(ds.frames[3].image_paths[0], ds.cameras[0]).at<std::uint8_t>(5, 5), 43);
}

TEST_F(EurocTest, GnssFixOutOfRangeIsSkippedWithWarning) {
  writeGnss({"47.3667,8.55,500.0,1.5,3.0", "95.0,8.55,500.0,1.5,3.0", "47.3669,8.55,500.0,1.5,3"});
  const Dataset ds = read();
  ASSERT_EQ(ds.gnss.size(), 2U);
  EXPECT_DOUBLE_EQ(ds.gnss[1].lat_deg, 47.3669);
  ASSERT_EQ(ds.warnings.size(), 1U);
  EXPECT_THAT(ds.warnings[0], HasSubstr("gnss0/data.csv"));
  EXPECT_THAT(ds.warnings[0], HasSubstr("1 fixes"));
  EXPECT_THAT(ds.warnings[0], HasSubstr("line 3"));
}

TEST_F(EurocTest, ImuRowWithSixFields) {
  writeImu(10);
  test::replaceLine(imuCsv(), 4, fmt::format("{},0.01,-0.02,0.03,0.1,0.2", kT0 + 2 * kImuPeriodNs));
  EXPECT_TRUE(names(error(), imuCsv(), 4, "expected 7 fields, got 6"));
}

TEST_F(EurocTest, ImuValueInfinite) {
  writeImu(10);
  test::replaceLine(imuCsv(), 6,
                    fmt::format("{},0.01,-0.02,0.03,inf,0.2,9.81", kT0 + 4 * kImuPeriodNs));
  EXPECT_TRUE(names(error(), imuCsv(), 6, "non-finite acceleration 'inf'"));
}

TEST_F(EurocTest, ImuTimestampsNotIncreasing) {
  writeImu(10);
  test::replaceLine(imuCsv(), 7, fmt::format("{},0,0,0,0,0,9.81", kT0 + 2 * kImuPeriodNs));
  EXPECT_TRUE(names(error(), imuCsv(), 7, "timestamp not increasing"));
  test::replaceLine(imuCsv(), 7, fmt::format("{},0,0,0,0,0,9.81", kT0 + 4 * kImuPeriodNs));
  EXPECT_TRUE(names(error(), imuCsv(), 7, "duplicate timestamp"));
}

// The IMU noise is checked where it is read, so the error names sensor.yaml's line (not a config
// key the user never wrote).
TEST_F(EurocTest, ImuNoiseMustBeStatedAndPositive) {
  writeImu(10);
  const fs::path yaml = mav0() / "imu0" / "sensor.yaml";
  test::replaceLine(yaml, 5, "gyroscope_random_walk: -2.0e-05");
  EXPECT_TRUE(names(error(), yaml, 5, "'gyroscope_random_walk' must be a positive number"));
  test::replaceLine(yaml, 5, "gyroscope_random_walk: .nan");
  EXPECT_TRUE(names(error(), yaml, 5, "must be a positive number"));
  test::replaceLine(yaml, 5, "# none");
  EXPECT_TRUE(names(error(), yaml, 0, "missing 'gyroscope_random_walk'"));
}

TEST_F(EurocTest, CameraWithoutSensorYaml) {
  writeImu(10);
  writeCamera("cam0", 2);
  fs::remove(mav0() / "cam0" / "sensor.yaml");
  EXPECT_TRUE(names(error(), mav0() / "cam0" / "sensor.yaml", 0, "not found"));
}

// TUM VI's layout: EuRoC folders whose sensor.yaml names the equidistant (fisheye) model.
TEST_F(EurocTest, EquidistantCamerasAreFisheyeAndOtherModelsAreRefused) {
  writeImu(10);
  writeCamera("cam0", 2);
  const fs::path yaml = mav0() / "cam0" / "sensor.yaml";
  test::replaceLine(yaml, 7, "distortion_model: equidistant");
  test::replaceLine(yaml, 8, "distortion_coefficients: [0.0034, 0.0007, -0.0021, 0.0002]");
  const Dataset ds = read();
  ASSERT_EQ(ds.cameras.size(), 1U);
  EXPECT_EQ(ds.cameras[0].distortion_model, Distortion::kEquidistant);
  EXPECT_EQ(ds.cameras[0].distortion, (std::vector<double>{0.0034, 0.0007, -0.0021, 0.0002}));

  writeCamera("cam0", 2);
  EXPECT_EQ(read().cameras[0].distortion_model, Distortion::kRadtan);
  test::replaceLine(yaml, 7, "distortion_model: fov");
  EXPECT_TRUE(names(error(), yaml, 7, "unsupported camera model 'pinhole' / 'fov'"));
}

TEST_F(EurocTest, MalformedSensorYaml) {
  writeCamera("cam0", 2);
  const fs::path yaml = mav0() / "cam0" / "sensor.yaml";
  test::replaceLine(yaml, 4, "resolution: [32, 16");  // unclosed flow sequence
  const std::string syntax = error();
  EXPECT_THAT(syntax, ::testing::StartsWith(yaml.string() + ":"));  // yaml-cpp's line
  EXPECT_THAT(syntax, HasSubstr("sequence"));

  writeCamera("cam0", 2);
  test::replaceLine(yaml, 6, "intrinsics: [20.0, abc, 16.0, 8.0]");
  EXPECT_TRUE(names(error(), yaml, 6, "'intrinsics' holds a non-numeric value"));

  writeCamera("cam0", 2);
  test::replaceLine(yaml, 4, "resolution: [32]");
  EXPECT_TRUE(names(error(), yaml, 4, "'resolution' must be a list of 2 numbers"));
}

// ---- lazy image loading (through a synthetic EuRoC camera) ----

class ImageLoaderTest : public EurocTest {
 protected:
  void SetUp() override {
    writeCamera("cam0", 2);
    ds_ = read();
    ASSERT_EQ(ds_.frames.size(), 2U);
  }
  // The error loading frame `frame` of cam0 after `damage` rewrote its file.
  std::string errorAfter(int frame, const std::function<void(const fs::path&)>& damage) {
    damage(imagePath("cam0", frame));
    return inputError([&] { (void)loadGrayImage(imagePath("cam0", frame), ds_.cameras[0]); });
  }
  Dataset ds_;
};

TEST_F(ImageLoaderTest, LoadsGreyImageOfTheCalibratedSize) {
  const cv::Mat image = loadGrayImage(ds_.frames[1].image_paths[0], ds_.cameras[0]);
  EXPECT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.cols, 32);
  EXPECT_EQ(image.rows, 16);
  EXPECT_EQ(image.at<std::uint8_t>(3, 3), 41);
}

TEST_F(ImageLoaderTest, WrongSizeNamesBothSizes) {
  const std::string message = errorAfter(1, [](const fs::path& file) {
    cv::imwrite(file.string(), cv::Mat(16, 40, CV_8UC1, cv::Scalar(9)));
  });
  EXPECT_TRUE(names(message, imagePath("cam0", 1), 0, "40x16"));
  EXPECT_THAT(message, HasSubstr("32x16"));
  EXPECT_THAT(message, HasSubstr("cam0"));
}

TEST_F(ImageLoaderTest, RandomBytesAreUnreadable) {
  const std::string message = errorAfter(0, [](const fs::path& file) {
    std::mt19937 rng(7);
    std::string bytes(600, '\0');
    for (auto& b : bytes) b = static_cast<char>(rng() & 0xFF);
    test::writeText(file, bytes);
  });
  EXPECT_TRUE(names(message, imagePath("cam0", 0), 0, "unreadable"));
}

TEST_F(ImageLoaderTest, TruncatedOrDamagedPngIsUnreadable) {
  const auto truncate = [](const fs::path& file) {
    const std::string png = test::readText(file);
    test::writeText(file, png.substr(0, png.size() - 20));
  };
  EXPECT_TRUE(names(errorAfter(0, truncate), imagePath("cam0", 0), 0, "truncated PNG"));
  const auto flip = [](const fs::path& file) {
    std::string png = test::readText(file);
    png[png.find("IDAT") + 6] ^= 0x55;
    test::writeText(file, png);
  };
  EXPECT_TRUE(names(errorAfter(1, flip), imagePath("cam0", 1), 0, "IDAT fails its CRC"));
}

TEST_F(ImageLoaderTest, EmptyOrMissingFile) {
  const auto empty = [](const fs::path& file) { test::writeText(file, ""); };
  EXPECT_TRUE(names(errorAfter(0, empty), imagePath("cam0", 0), 0, "unreadable"));
  const auto remove = [](const fs::path& file) { fs::remove(file); };
  EXPECT_TRUE(names(errorAfter(1, remove), imagePath("cam0", 1), 0, "image file not found"));
}

TEST_F(EurocTest, ListedImageMissingIsSkippedWithWarning) {
  writeCamera("cam0", 3);
  fs::remove(imagePath("cam0", 1));
  const Dataset ds = read();
  EXPECT_EQ(ds.frames.size(), 2U);
  ASSERT_EQ(ds.warnings.size(), 1U);
  EXPECT_THAT(ds.warnings[0], HasSubstr("1 listed images not found"));
  EXPECT_THAT(ds.warnings[0], HasSubstr("line 3"));
}

}  // namespace
}  // namespace gvio::io
