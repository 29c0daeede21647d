// The fault matrix, input faults (docs/reliability.md): one fault in an otherwise valid drive.
// A damaged image costs its frame (warned, counted in report.json); everything else the run
// cannot trust stops it before any output with one line naming the file and line (exit 2).
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "faults/fault_support.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr const char* kImage = "image_01/data/0000000050.png";

nlohmann::json report(const FaultCase& c) {
  return nlohmann::json::parse(readText(c.out() / "report.json"));
}

// A run that completes despite the fault: exit 0, a complete report, finite outputs.
void expectCompleted(const FaultCase& c, const CommandResult& r) {
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(reportStatus(c.out()), "complete");
  expectFiniteOutputs(c.out());
  expectNoTemporaries(c.out());
}

// A run refused at the dataset: exit 2, the one line, and no run folder at all.
void expectRefused(const FaultCase& c, const CommandResult& r, const std::string& where,
                   const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const std::string line = errorLine(r);
  EXPECT_THAT(line, HasSubstr((c.dataset() / where).string())) << line;
  EXPECT_THAT(line, HasSubstr(what));
  EXPECT_FALSE(fs::exists(c.out())) << "a refused run wrote a folder";
}

TEST(FaultInputs, TruncatedImageSkipsItsFrame) {
  FaultCase c("truncated_image");
  const std::string png = readText(c.file(kImage));
  writeText(c.file(kImage), png.substr(0, png.size() / 3));
  const CommandResult r = c.run();
  expectCompleted(c, r);
  EXPECT_THAT(r.err, HasSubstr(c.file(kImage).string() + ": unreadable image: truncated PNG"));
  EXPECT_EQ(report(c)["counts"]["frames_skipped_unreadable"], 1);
}

TEST(FaultInputs, ZeroByteImageSkipsItsFrame) {
  FaultCase c("zero_image");
  writeText(c.file(kImage), "");
  const CommandResult r = c.run();
  expectCompleted(c, r);
  EXPECT_THAT(r.err, HasSubstr(c.file(kImage).string() + ": unreadable image"));
  EXPECT_EQ(report(c)["counts"]["frames_skipped_unreadable"], 1);
}

TEST(FaultInputs, ImageOfTheWrongSizeSkipsItsFrame) {
  FaultCase c("wrong_size_image");
  const cv::Mat image = cv::imread(c.file(kImage).string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(image.empty());
  cv::Mat half;
  cv::resize(image, half, cv::Size(image.cols / 2, image.rows / 2));
  ASSERT_TRUE(cv::imwrite(c.file(kImage).string(), half));
  const CommandResult r = c.run();
  expectCompleted(c, r);
  EXPECT_THAT(r.err, HasSubstr(c.file(kImage).string()));
  EXPECT_EQ(report(c)["counts"]["frames_skipped_unreadable"], 1);
}

TEST(FaultInputs, MissingImageIsRefused) {
  FaultCase c("missing_image");
  fs::remove(c.file(kImage));
  expectRefused(c, c.run(), kImage, "image file not found");
}

TEST(FaultInputs, DuplicatedTimestampIsRefused) {
  FaultCase c("duplicate_stamp");
  replaceLine(c.file("image_00/timestamps.txt"), 51, "2011-10-03 12:55:38.900000000");
  expectRefused(c, c.run(), "image_00/timestamps.txt:51", "duplicate timestamp");
}

TEST(FaultInputs, DecreasingTimestampIsRefused) {
  FaultCase c("decreasing_stamp");
  replaceLine(c.file("image_00/timestamps.txt"), 51, "2011-10-03 12:55:38.800000000");
  expectRefused(c, c.run(), "image_00/timestamps.txt:51", "timestamp not increasing");
}

// Replaces field `index` (0-based) of a one-line oxts record.
void setOxtsField(const fs::path& file, std::size_t index, const std::string& value) {
  std::istringstream in(readText(file));
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  ASSERT_LT(index, fields.size());
  fields[index] = value;
  std::string line;
  for (const auto& f : fields) line += (line.empty() ? "" : " ") + f;
  writeText(file, line + "\n");
}

TEST(FaultInputs, NanImuSampleIsRefused) {
  FaultCase c("nan_imu");
  setOxtsField(c.file("oxts/data/0000000300.txt"), 11, "nan");  // ax
  expectRefused(c, c.run(), "oxts/data/0000000300.txt:1", "non-finite oxts value 'nan'");
}

TEST(FaultInputs, InfImuSampleIsRefused) {
  FaultCase c("inf_imu");
  setOxtsField(c.file("oxts/data/0000000300.txt"), 20, "-inf");  // wz
  expectRefused(c, c.run(), "oxts/data/0000000300.txt:1", "non-finite oxts value '-inf'");
}

// Drops the oxts records from `first` to `last` (exclusive) and renumbers the rest, as a logger
// that lost 5 s of IMU would have written them.
void dropOxts(const fs::path& drive, std::size_t first, std::size_t last) {
  const fs::path dir = drive / "oxts";
  std::istringstream stamps(readText(dir / "timestamps.txt"));
  std::vector<std::string> kept_stamps, kept_records;
  std::size_t i = 0;
  for (std::string line; std::getline(stamps, line); ++i) {
    const fs::path record = dir / "data" / fmt::format("{:010d}.txt", i);
    if (i < first || i >= last) {
      kept_stamps.push_back(line);
      kept_records.push_back(readText(record));
    }
    fs::remove(record);
  }
  std::string text;
  for (std::size_t k = 0; k < kept_stamps.size(); ++k) {
    writeText(dir / "data" / fmt::format("{:010d}.txt", k), kept_records[k]);
    text += kept_stamps[k] + "\n";
  }
  writeText(dir / "timestamps.txt", text);
}

TEST(FaultInputs, FiveSecondImuGapIsBridgedOnVision) {
  FaultCase c("imu_gap");
  dropOxts(c.dataset(), 300, 800);  // t = 3 s .. 8 s
  const CommandResult r = c.run();
  expectCompleted(c, r);
  EXPECT_THAT(r.err, HasSubstr("1 gap(s) in the IMU longer than vio.max_imu_gap_s"));
  // Vision carries the 5 s.
  const double ape = report(c)["evaluation"]["ape_se3"]["rmse"].get<double>();
  std::printf("5 s IMU gap: APE (SE3) %.3f m\n", ape);
  EXPECT_LT(ape, 0.5);
}

TEST(FaultInputs, ACameraBlindForMostOfTheDriveMakesThePartialRun) {
  FaultCase c("blind_camera");
  // The first 7 s of both cameras see a grey wall: no corner, so the VIO initialises at about
  // 8 s of a 10 s drive. The run finishes (exit 0) and says it is partial, in report.json and
  // in its summary line, instead of "complete".
  const cv::Mat grey =
      cv::imread(c.file("image_00/data/0000000000.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(grey.empty());
  for (const char* cam : {"image_00", "image_01"}) {
    for (int i = 0; i < 70; ++i) {
      const fs::path image = c.file(fmt::format("{}/data/{:010d}.png", cam, i));
      ASSERT_TRUE(cv::imwrite(image.string(), cv::Mat(grey.size(), grey.type(), cv::Scalar(128))));
    }
  }
  const CommandResult r = c.run();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(reportStatus(c.out()), "partial");
  EXPECT_THAT(r.err, HasSubstr("partial: the trajectory covers "));
  const nlohmann::json coverage = report(c)["coverage"];
  std::cout << "coverage: " << coverage.dump() << "\n";
  EXPECT_NEAR(coverage["input_s"].get<double>(), 10.0, 0.01);
  EXPECT_LT(coverage["fraction"].get<double>(), 0.5);
  EXPECT_GT(coverage["output_s"].get<double>(), 0.5);  // it did start, late
  expectFiniteOutputs(c.out());
  expectNoTemporaries(c.out());
}

TEST(FaultInputs, SingularCalibrationIsRefused) {
  FaultCase c("singular_calibration");
  const fs::path calib = c.file("calib_cam_to_cam.txt");
  std::istringstream in(readText(calib));
  std::size_t n = 0, k_line = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    if (line.rfind("K_01:", 0) == 0) k_line = n;
  }
  ASSERT_GT(k_line, 0u);
  replaceLine(calib, k_line, "K_01: 718.856 0 607.1928 0 718.856 185.2157 0 0 0");
  expectRefused(c, c.run(), "calib_cam_to_cam.txt:" + std::to_string(k_line),
                "K_01 is not a camera matrix");
}

TEST(FaultInputs, ConfigValueOfTheWrongTypeIsRefused) {
  FaultCase c("config_type");
  CommandResult r = c.run("--set imu.acc_noise_density=abc");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r), HasSubstr("--set imu.acc_noise_density: bad value 'abc'"));
  const fs::path config = c.dataset().parent_path() / "config.yaml";
  writeText(config, "imu:\n  acc_noise_density: [1, 2]\n");
  r = c.run("--config " + quoted(config));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(errorLine(r), HasSubstr(config.string() + ":2: bad value"));
  EXPECT_FALSE(fs::exists(c.out()));
}

}  // namespace
}  // namespace gvio::test
