// `gvio inspect` end to end through the built binary: the summary of a valid drive (text and
// JSON), and the one-line error with exit code 2 for broken input and bad usage.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "support/fixtures.hpp"

namespace gvio {
namespace {

namespace fs = std::filesystem;
using test::quoted;
using ::testing::HasSubstr;
using ::testing::Not;

// `gvio inspect --dataset <dataset> --no-progress <extra>`.
test::CommandResult inspect(const fs::path& dataset, const std::string& extra = "") {
  return test::runGvio("inspect --dataset " + quoted(dataset) + " --no-progress " + extra);
}

// Exit code 2 and exactly one stderr line, an "[error]" naming `file`.
::testing::AssertionResult failsOnOneLine(const test::CommandResult& r, const fs::path& file) {
  if (r.exit_code != 2) {
    return ::testing::AssertionFailure() << "exit code " << r.exit_code << ", stderr: " << r.err;
  }
  if (std::count(r.err.begin(), r.err.end(), '\n') != 1 || !r.err.ends_with('\n')) {
    return ::testing::AssertionFailure() << "stderr is not one line: '" << r.err << "'";
  }
  if (r.err.find("[error]") == std::string::npos ||
      r.err.find(file.filename().string()) == std::string::npos) {
    return ::testing::AssertionFailure()
           << "stderr '" << r.err << "' lacks [error] or " << file.filename();
  }
  return ::testing::AssertionSuccess();
}

class CliInspectTest : public ::testing::Test {
 protected:
  void SetUp() override { drive_ = test::writeKittiFixture(tmp_.path(), test::KittiFixture{}); }
  [[nodiscard]] fs::path image(int cam, int frame) const {
    return drive_ / ("image_0" + std::to_string(cam)) / "data" /
           ("000000000" + std::to_string(frame) + ".png");
  }

  test::TempDir tmp_{"cli_inspect"};
  fs::path drive_;
};

TEST_F(CliInspectTest, SummarisesValidDriveAsTextAndJson) {
  const fs::path json_file = tmp_.path() / "out" / "summary.json";
  fs::create_directories(json_file.parent_path());
  const auto r = inspect(drive_, "--json " + quoted(json_file));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("kitti-raw"));
  EXPECT_THAT(r.out, HasSubstr("64x24"));
  EXPECT_THAT(r.out, HasSubstr("12 decoded"));
  EXPECT_EQ(r.err.find("[error]"), std::string::npos) << r.err;

  ASSERT_TRUE(fs::is_regular_file(json_file));
  const auto j = nlohmann::json::parse(test::readText(json_file));
  EXPECT_EQ(j["format"], "kitti-raw");
  EXPECT_EQ(j["variant"], "extract");
  EXPECT_EQ(j["cameras"]["count"], 6);
  EXPECT_EQ(j["images_checked"], 12);
  EXPECT_EQ(j["imu"]["count"], 60);
  EXPECT_EQ(j["gnss"]["count"], 60);
  EXPECT_NEAR(j["cameras"]["stereo_baseline_m"].get<double>(), 0.537, 1e-6);
  EXPECT_EQ(j["cameras"]["models"][0]["width"], 64);
  EXPECT_EQ(j["cameras"]["models"][0]["distortion_model"], "none");  // D_00: 0 0 0 0 0
  EXPECT_THAT(r.out, Not(HasSubstr("distortion")));
  EXPECT_TRUE(j["warnings"].empty());
}

TEST_F(CliInspectTest, MissingDataset) {
  const fs::path missing = tmp_.path() / "no_such_drive";
  EXPECT_TRUE(failsOnOneLine(inspect(missing), missing));
}

TEST_F(CliInspectTest, MalformedOxtsLine) {
  const fs::path rec = drive_ / "oxts" / "data" / "0000000004.txt";
  test::writeText(rec, "49.0 8.4 116.4 not-a-number\n");
  const auto r = inspect(drive_);
  EXPECT_TRUE(failsOnOneLine(r, rec));
  EXPECT_THAT(r.err, HasSubstr("0000000004.txt:1:"));
}

TEST_F(CliInspectTest, WrongImageSize) {
  cv::imwrite(image(1, 3).string(), cv::Mat(24, 32, CV_8UC1, cv::Scalar(128)));
  const auto r = inspect(drive_);
  EXPECT_TRUE(failsOnOneLine(r, image(1, 3)));
  EXPECT_THAT(r.err, HasSubstr("32x24"));
  EXPECT_THAT(r.err, HasSubstr("64x24"));
}

TEST_F(CliInspectTest, CorruptPng) {
  test::writeText(image(0, 5), "\x89PNG but then nothing that libpng could decode at all");
  const auto r = inspect(drive_);
  EXPECT_TRUE(failsOnOneLine(r, image(0, 5)));
  EXPECT_THAT(r.err, HasSubstr("unreadable"));
}

TEST_F(CliInspectTest, TruncatedPng) {
  const std::string png = test::readText(image(1, 2));
  test::writeText(image(1, 2), png.substr(0, png.size() / 2));  // header intact, data cut
  const auto r = inspect(drive_);
  EXPECT_TRUE(failsOnOneLine(r, image(1, 2)));
  EXPECT_THAT(r.err, HasSubstr("unreadable"));
}

TEST(CliUsage, HelpListsInspect) {
  const auto r = test::runGvio("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("inspect"));
}

TEST(CliUsage, UnknownOptionIsBadUsage) {
  const auto r = test::runGvio("inspect --dataset . --no-such-option");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.out + r.err, HasSubstr("--no-such-option"));
}

// A dataset that states its IMU noise (EuRoC sensor.yaml, the simulator's own figures): used
// times imu.dataset_noise_scale unless imu.* is preferred, which is never scaled.
TEST(CliInspectImuNoise, TheStatedNoiseTimesTheScale) {
  const fs::path drive = test::cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 4 --format euroc",
                  GVIO_SOURCE_DIR));
  test::TempDir dir("cli_inspect_noise");
  const auto noise = [&](const std::string& set) {
    const fs::path json = dir.path() / "summary.json";
    const test::CommandResult r = inspect(drive, "--quick --json " + quoted(json) + " " + set);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(test::readText(json))["imu"]["noise"];
  };
  const nlohmann::json stated = noise("");
  EXPECT_EQ(stated["source"], "dataset");
  const nlohmann::json scaled = noise("--set imu.dataset_noise_scale=3");
  EXPECT_EQ(scaled["source"], "dataset");
  for (const char* key :
       {"acc_noise_density", "gyr_noise_density", "acc_random_walk", "gyr_random_walk"}) {
    EXPECT_GT(stated[key].get<double>(), 0.0) << key;
    EXPECT_NEAR(scaled[key].get<double>(), 3.0 * stated[key].get<double>(),
                1e-12 * stated[key].get<double>())
        << key;
  }
  const nlohmann::json config = noise(
      "--set imu.dataset_noise_scale=3 --set imu.prefer_dataset_noise=false "
      "--set imu.acc_noise_density=0.05");
  EXPECT_EQ(config["source"], "config");
  EXPECT_DOUBLE_EQ(config["acc_noise_density"].get<double>(), 0.05);
}

TEST(CliUsage, UnknownFormatIsBadUsage) {
  const auto r = test::runGvio("inspect --dataset . --format bogus");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.out + r.err, HasSubstr("bogus"));
}

// A path the file system refuses outright is bad input (exit 2, one line naming it), not an
// internal error, whichever command meets it first.
TEST(CliUsage, APathTooLongForTheFileSystemIsBadInput) {
  const std::string too_long =
      (std::filesystem::temp_directory_path() / std::string(400, 'a')).string();
  for (const std::string& args :
       {"render --no-progress --run " + too_long + " --out " + too_long + ".png",
        "inspect --no-progress --dataset " + too_long,
        "eval --ref " + too_long + " --est " + too_long}) {
    const auto r = test::runGvio(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_THAT(r.err, Not(HasSubstr("internal error"))) << args;
    EXPECT_THAT(r.err, HasSubstr(std::string(400, 'a'))) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  }
}

TEST(CliUsage, MissingRequiredDatasetIsBadUsage) {
  EXPECT_EQ(test::runGvio("inspect").exit_code, 2);
  EXPECT_EQ(test::runGvio("").exit_code, 2);  // a subcommand is required
}

}  // namespace
}  // namespace gvio
