#include "cli/config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>

#include "io/input_error.hpp"
#include "support/fixtures.hpp"

namespace gvio::cli {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

const fs::path kConfigDir = fs::path(GVIO_SOURCE_DIR) / "assets" / "config";

std::string errorOf(const ConfigSources& sources) {
  try {
    loadConfig(sources);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

TEST(Config, DefaultsValidate) {
  EXPECT_NO_THROW(AppConfig{}.validate());
}

// default.yaml must document every key the schema knows, and nothing else.
TEST(Config, DefaultYamlDocumentsEveryKey) {
  std::vector<std::string> unknown;
  const AppConfig loaded = loadConfig({kConfigDir / "default.yaml", {}}, &unknown);
  EXPECT_TRUE(unknown.empty()) << unknown.front();
  const std::string text = test::readText(kConfigDir / "default.yaml");
  AppConfig config;
  for (const auto& key : configKeys(config)) {
    const std::string leaf = key.name.substr(key.name.find('.') + 1);
    EXPECT_THAT(text, HasSubstr("\n  " + leaf + ":")) << key.name << " is not documented";
  }
  // The file states the defaults, so loading it changes nothing.
  EXPECT_EQ(dumpConfigYaml(loaded), dumpConfigYaml(AppConfig{}));
}

TEST(Config, PresetsLoadWithoutUnknownKeys) {
  for (const char* preset : {"kitti.yaml", "euroc.yaml"}) {
    std::vector<std::string> unknown;
    EXPECT_NO_THROW(loadConfig({kConfigDir / preset, {}}, &unknown)) << preset;
    EXPECT_TRUE(unknown.empty()) << preset;
  }
  EXPECT_FALSE(loadConfig({kConfigDir / "kitti.yaml", {}}).imu.prefer_dataset_noise);
}

TEST(Config, FileThenOverrides) {
  test::TempDir dir("config");
  test::writeText(dir.path() / "c.yaml",
                  "dataset:\n  gap_factor: 4\nimu:\n  acc_noise_density: 0.01\n");
  const AppConfig c = loadConfig(
      {dir.path() / "c.yaml", {"dataset.gap_factor=6", "imu.prefer_dataset_noise=false"}});
  EXPECT_DOUBLE_EQ(c.dataset.gap_factor, 6.0);
  EXPECT_DOUBLE_EQ(c.imu.noise.acc_noise_density, 0.01);
  EXPECT_FALSE(c.imu.prefer_dataset_noise);
}

// The dataset's stated noise, scaled, unless the config's is preferred; imu.* never scaled.
TEST(Config, ImuNoiseChoiceScalesTheDatasetsNoiseOnly) {
  run::ImuConfig c;
  c.dataset_noise_scale = 2.5;
  c.noise.acc_noise_density = 0.01;
  ImuNoise stated;
  stated.acc_noise_density = 1e-3;
  stated.gyr_noise_density = 2e-4;
  stated.acc_random_walk = 3e-5;
  stated.gyr_random_walk = 4e-6;
  const run::ImuConfig::Choice from_dataset = c.choose(stated);
  EXPECT_STREQ(from_dataset.source, "dataset");
  EXPECT_DOUBLE_EQ(from_dataset.noise.acc_noise_density, 2.5e-3);
  EXPECT_DOUBLE_EQ(from_dataset.noise.gyr_noise_density, 5e-4);
  EXPECT_DOUBLE_EQ(from_dataset.noise.acc_random_walk, 7.5e-5);
  EXPECT_DOUBLE_EQ(from_dataset.noise.gyr_random_walk, 1e-5);
  const run::ImuConfig::Choice without = c.choose(std::nullopt);
  EXPECT_STREQ(without.source, "config");
  EXPECT_DOUBLE_EQ(without.noise.acc_noise_density, 0.01);
  c.prefer_dataset_noise = false;
  EXPECT_STREQ(c.choose(stated).source, "config");
  EXPECT_DOUBLE_EQ(c.choose(stated).noise.acc_noise_density, 0.01);
}

TEST(Config, UnknownFileKeyWarnsAndIsReported) {
  test::TempDir dir("config");
  test::writeText(dir.path() / "c.yaml", "dataset:\n  gap_factr: 4\n");
  std::vector<std::string> unknown;
  const AppConfig c = loadConfig({dir.path() / "c.yaml", {}}, &unknown);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "dataset.gap_factr");
  EXPECT_DOUBLE_EQ(c.dataset.gap_factor, 2.5);
}

TEST(Config, BadValueNamesFileLineAndKey) {
  test::TempDir dir("config");
  const fs::path file = dir.path() / "c.yaml";
  test::writeText(file, "dataset:\n  gap_factor: fast\n");
  const std::string err = errorOf({file, {}});
  EXPECT_THAT(err, HasSubstr(file.string() + ":2:"));
  EXPECT_THAT(err, HasSubstr("dataset.gap_factor"));
}

TEST(Config, ValidateRejectsOutOfRange) {
  EXPECT_THAT(errorOf({std::nullopt, {"dataset.gap_factor=0.5"}}), HasSubstr("dataset.gap_factor"));
  EXPECT_THAT(errorOf({std::nullopt, {"imu.gyr_noise_density=-1"}}),
              HasSubstr("imu.gyr_noise_density"));
  EXPECT_THAT(errorOf({std::nullopt, {"dataset.kitti_gnss_source=gps"}}),
              HasSubstr("kitti_gnss_source"));
  EXPECT_THAT(errorOf({std::nullopt, {"imu.dataset_noise_scale=0"}}),
              HasSubstr("imu.dataset_noise_scale must be a positive number"));
  EXPECT_THAT(errorOf({std::nullopt, {"imu.dataset_noise_scale=-2"}}),
              HasSubstr("imu.dataset_noise_scale"));
  EXPECT_THAT(errorOf({std::nullopt, {"imu.prefer_dataset_noise=maybe"}}),
              HasSubstr("true or false"));
  EXPECT_THAT(errorOf({std::nullopt, {"dataset.gap_factor=nan"}}), HasSubstr("finite"));
}

// A value that parses but fails validation is reported where it was written: the file's line, or
// the --set that gave it (a later --set wins over the file, and so does its error).
TEST(Config, ValidationErrorsNameWhereTheValueCameFrom) {
  test::TempDir dir("config");
  const fs::path file = dir.path() / "c.yaml";
  test::writeText(file, "dataset:\n  gap_factor: 3\nimu:\n  gyr_noise_density: -1\n");
  const std::string from_file = errorOf({file, {}});
  EXPECT_THAT(from_file, HasSubstr(file.string() + ":4: "));
  EXPECT_THAT(from_file, HasSubstr("imu.gyr_noise_density"));
  const std::string from_set = errorOf({file, {"imu.gyr_noise_density=-2"}});
  EXPECT_THAT(from_set, HasSubstr("--set imu.gyr_noise_density: "));
  EXPECT_THAT(from_set, testing::Not(HasSubstr(file.string())));
  // The libraries name their own fields (tracker.max_features): the dotted key is found.
  test::writeText(file, "vio:\n  tracker:\n    max_features: 0\n");
  EXPECT_THAT(errorOf({file, {}}), HasSubstr(file.string() + ":3: "));
}

TEST(Config, OverrideErrors) {
  EXPECT_THAT(errorOf({std::nullopt, {"dataset.nope=1"}}),
              HasSubstr("unknown config key 'dataset.nope'"));
  EXPECT_THAT(errorOf({std::nullopt, {"gap_factor"}}), HasSubstr("expected key=value"));
}

// A key replaced by one in another unit: in --set an error that names the new key; in a file (a
// run folder's config.yaml from before the change) ignored and reported like an unknown key, the
// rest of the file applied.
TEST(Config, AReplacedKeyNamesItsReplacement) {
  test::TempDir dir("config");
  const fs::path file = dir.path() / "c.yaml";
  test::writeText(file, "vio:\n  window_size: 12\n  keyframe_parallax_px: 15\n");
  std::vector<std::string> unknown;
  const AppConfig c = loadConfig({file, {}}, &unknown);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0], "vio.keyframe_parallax_px");
  EXPECT_EQ(c.vio.estimator.window_size, 12);
  EXPECT_DOUBLE_EQ(c.vio.estimator.keyframe_parallax_deg, 0.8);
  EXPECT_THAT(errorOf({std::nullopt, {"vio.keyframe_parallax_px=15"}}),
              HasSubstr("--set: 'vio.keyframe_parallax_px' was replaced by "
                        "'vio.keyframe_parallax_deg'"));
  EXPECT_THAT(errorOf({std::nullopt, {"vio.keyframe_parallax_deg=0"}}),
              HasSubstr("vio.keyframe_parallax_deg"));
  EXPECT_THAT(errorOf({std::nullopt, {"vio.keyframe_parallax_deg=50"}}),
              HasSubstr("vio.keyframe_parallax_deg"));
  EXPECT_TRUE(errorOf({std::nullopt, {"vio.keyframe_parallax_deg=1.25"}}).empty());
}

TEST(Config, FileErrors) {
  test::TempDir dir("config");
  EXPECT_THAT(errorOf({dir.path() / "missing.yaml", {}}), HasSubstr("not found"));
  test::writeText(dir.path() / "bad.yaml", "dataset: [1, 2\n");
  EXPECT_THAT(errorOf({dir.path() / "bad.yaml", {}}), HasSubstr("YAML syntax"));
  test::writeText(dir.path() / "list.yaml", "- 1\n- 2\n");
  EXPECT_THAT(errorOf({dir.path() / "list.yaml", {}}), HasSubstr("mapping"));
  test::writeText(dir.path() / "empty.yaml", "");
  EXPECT_TRUE(errorOf({dir.path() / "empty.yaml", {}}).empty());
}

// vio.max_iterations: "auto" leaves the choice to the estimator's mode; a number is used as given.
TEST(Config, SolverIterationsAreAutoOrAPositiveInteger) {
  AppConfig c = loadConfig({std::nullopt, {}});
  EXPECT_EQ(c.vio.estimator.max_iterations, 0);
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("max_iterations: auto"));
  c.vio.estimator.mode = odometry::VioMode::kStereoImu;
  EXPECT_EQ(c.vio.estimator.solverIterations(), 2);
  c.vio.estimator.mode = odometry::VioMode::kStereo;
  EXPECT_EQ(c.vio.estimator.solverIterations(), 4);
  c.vio.estimator.mode = odometry::VioMode::kMonoImu;
  EXPECT_EQ(c.vio.estimator.solverIterations(), 4);
  c = loadConfig({std::nullopt, {"vio.max_iterations=7"}});
  EXPECT_EQ(c.vio.estimator.solverIterations(), 7);
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("max_iterations: 7"));
  EXPECT_THAT(errorOf({std::nullopt, {"vio.max_iterations=0"}}),
              HasSubstr("expected auto or an integer >= 1"));
  EXPECT_THAT(errorOf({std::nullopt, {"vio.max_iterations=many"}}),
              HasSubstr("bad value 'many' for vio.max_iterations"));
  EXPECT_THAT(errorOf({std::nullopt, {"vio.max_iterations=101"}}), HasSubstr("max_iterations"));
}

// fusion.vio_drift_fraction, vio_sigma_floor_m, vio_rot_floor_rad: "auto" takes the model
// measured for the run's VIO mode (tighter for stereo+IMU); a value set wins in every mode.
TEST(Config, FusionVioNoiseIsAutoByModeOrAsSet) {
  AppConfig c = loadConfig({std::nullopt, {}});
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("vio_drift_fraction: auto"));
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("vio_rot_floor_rad: auto"));
  const fusion::FusionConfig library;  // the library's defaults: the model of the other modes
  const fusion::FusionConfig stereo_imu = c.fusion.fusionFor(odometry::VioMode::kStereoImu);
  EXPECT_DOUBLE_EQ(stereo_imu.vio_drift_fraction, 0.002);
  EXPECT_DOUBLE_EQ(stereo_imu.vio_sigma_floor_m, 0.01);
  EXPECT_DOUBLE_EQ(stereo_imu.vio_rot_floor_rad, 2e-4);
  EXPECT_DOUBLE_EQ(stereo_imu.vio_rot_drift_rad_per_m, library.vio_rot_drift_rad_per_m);
  for (const auto mode :
       {std::optional(odometry::VioMode::kMonoImu), std::optional(odometry::VioMode::kStereo),
        std::optional<odometry::VioMode>()}) {
    const fusion::FusionConfig f = c.fusion.fusionFor(mode);
    EXPECT_DOUBLE_EQ(f.vio_drift_fraction, library.vio_drift_fraction);
    EXPECT_DOUBLE_EQ(f.vio_sigma_floor_m, library.vio_sigma_floor_m);
    EXPECT_DOUBLE_EQ(f.vio_rot_floor_rad, library.vio_rot_floor_rad);
  }
  c = loadConfig(
      {std::nullopt, {"fusion.vio_drift_fraction=0.003", "fusion.vio_rot_floor_rad=1e-3"}});
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("vio_drift_fraction: 0.003"));
  for (const auto mode : {odometry::VioMode::kStereoImu, odometry::VioMode::kMonoImu}) {
    const fusion::FusionConfig f = c.fusion.fusionFor(mode);
    EXPECT_DOUBLE_EQ(f.vio_drift_fraction, 0.003);
    EXPECT_DOUBLE_EQ(f.vio_rot_floor_rad, 1e-3);
  }
  EXPECT_DOUBLE_EQ(c.fusion.fusionFor(odometry::VioMode::kStereoImu).vio_sigma_floor_m, 0.01);
  // A dumped config read back gives the same values.
  const test::TempDir dir("config_vio_noise");
  test::writeText(dir.path() / "c.yaml", dumpConfigYaml(c));
  const AppConfig back = loadConfig({dir.path() / "c.yaml", {}});
  EXPECT_DOUBLE_EQ(back.fusion.vio_drift_fraction, 0.003);
  EXPECT_DOUBLE_EQ(back.fusion.vio_sigma_floor_m, 0.0);
  EXPECT_THAT(errorOf({std::nullopt, {"fusion.vio_sigma_floor_m=0"}}),
              HasSubstr("expected auto or a positive number"));
  EXPECT_THAT(errorOf({std::nullopt, {"fusion.vio_drift_fraction=-1"}}),
              HasSubstr("bad value '-1' for fusion.vio_drift_fraction"));
  EXPECT_THAT(errorOf({std::nullopt, {"fusion.vio_rot_floor_rad=nan"}}),
              HasSubstr("fusion.vio_rot_floor_rad"));
}

TEST(Config, FoldedLandmarksAreDroppedWithTheImuUnlessSet) {
  AppConfig c = loadConfig({std::nullopt, {}});
  EXPECT_EQ(c.vio.estimator.folded_landmarks, odometry::FoldedLandmarks::kAuto);
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("folded_landmarks: auto"));
  c.vio.estimator.mode = odometry::VioMode::kStereoImu;
  EXPECT_TRUE(c.vio.estimator.foldedLandmarksDropped());
  c.vio.estimator.mode = odometry::VioMode::kMonoImu;
  EXPECT_TRUE(c.vio.estimator.foldedLandmarksDropped());
  c.vio.estimator.mode = odometry::VioMode::kStereo;
  EXPECT_FALSE(c.vio.estimator.foldedLandmarksDropped());
  c = loadConfig({std::nullopt, {"vio.folded_landmarks=reanchor"}});
  EXPECT_FALSE(c.vio.estimator.foldedLandmarksDropped());
  EXPECT_THAT(dumpConfigYaml(c), HasSubstr("folded_landmarks: reanchor"));
  c = loadConfig({std::nullopt, {"vio.folded_landmarks=drop"}});
  c.vio.estimator.mode = odometry::VioMode::kStereo;  // the run picks it for the dataset
  EXPECT_TRUE(c.vio.estimator.foldedLandmarksDropped());
  EXPECT_THAT(errorOf({std::nullopt, {"vio.folded_landmarks=keep"}}),
              HasSubstr("bad value 'keep' for vio.folded_landmarks: expected auto, drop or "
                        "reanchor"));
}

TEST(Config, DumpRoundTrips) {
  const AppConfig changed = loadConfig({std::nullopt,
                                        {"dataset.gap_factor=3.25", "imu.acc_random_walk=1e-5",
                                         "vio.max_iterations=3", "vio.folded_landmarks=reanchor"}});
  test::TempDir dir("config");
  test::writeText(dir.path() / "dump.yaml", dumpConfigYaml(changed));
  EXPECT_EQ(dumpConfigYaml(loadConfig({dir.path() / "dump.yaml", {}})), dumpConfigYaml(changed));
}

}  // namespace
}  // namespace gvio::cli
