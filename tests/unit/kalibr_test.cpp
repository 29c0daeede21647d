// Kalibr calibration files (issue 16): camchain.yaml (radtan and equidistant cameras) and imu.yaml
// into the dataset's cameras, IMU noise and camera clock; bad files named with their line; gvio run
// --calib on a simulated drive, as taken and as seen through a fisheye lens.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/input_error.hpp"
#include "io/kalibr.hpp"
#include "io/kalibr_writer.hpp"
#include "odometry/rectifier.hpp"
#include "support/euroc_camera.hpp"
#include "support/fixtures.hpp"
#include "support/tumvi_camera.hpp"

namespace gvio::io {
namespace {
using testing::AllOf;
using testing::HasSubstr;
namespace fs = std::filesystem;

std::string matrixYaml(const Eigen::Matrix4d& m, const std::string& indent) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{}- [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n", indent, m(r, 0), m(r, 1),
                       m(r, 2), m(r, 3));
  }
  return out;
}

// A Kalibr camchain block for `cam` (T_b_c: camera in the IMU body frame).
std::string cameraYaml(const std::string& name, const CameraModel& cam, double timeshift_s,
                       std::string distortion = "", const std::string& extra = "") {
  if (distortion.empty()) distortion = cam.distortion.empty() ? "none" : "radtan";
  const std::vector<double> d =
      cam.distortion.empty() ? std::vector<double>{0, 0, 0, 0} : cam.distortion;
  return fmt::format(
      "{}:\n  T_cam_imu:\n{}  camera_model: pinhole\n  distortion_coeffs: [{:.17g}, {:.17g}, "
      "{:.17g}, {:.17g}]\n  distortion_model: {}\n  intrinsics: [{:.17g}, {:.17g}, {:.17g}, "
      "{:.17g}]\n  resolution: [{}, {}]\n  rostopic: /{}/image_raw\n  timeshift_cam_imu: {}\n{}",
      name, matrixYaml(cam.T_b_c.inverse().matrix(), "  "), d[0], d[1], d[2], d[3], distortion,
      cam.fx, cam.fy, cam.cx, cam.cy, cam.width_px, cam.height_px, name, timeshift_s, extra);
}

constexpr const char* kImuYaml =
    "%YAML:1.0\nimu0:\n  accelerometer_noise_density: 0.0028\n  accelerometer_random_walk: "
    "0.00086\n  gyroscope_noise_density: 0.00016\n  gyroscope_random_walk: 2.2e-05\n  rostopic: "
    "/imu0\n  update_rate: 200.0\n";

TEST(Kalibr, CamchainAndImuFiles) {
  test::TempDir dir("kalibr");
  const CameraModel c0 = test::eurocCam0(), c1 = test::eurocCam1();
  const Eigen::Matrix4d T_c1_c0 = (c1.T_b_c.inverse() * c0.T_b_c).matrix();
  test::writeText(
      dir.path() / "camchain.yaml",
      cameraYaml("cam0", c0, 0.0125) +
          cameraYaml("cam1", c1, 0.0125, "radtan", "  T_cn_cnm1:\n" + matrixYaml(T_c1_c0, "  ")));
  test::writeText(dir.path() / "imu.yaml", kImuYaml);
  const KalibrCalibration k = readKalibr({dir.path() / "camchain.yaml", dir.path() / "imu.yaml"});
  ASSERT_EQ(k.cameras.size(), 2U);
  EXPECT_TRUE(k.warnings.empty()) << k.warnings.front();
  EXPECT_EQ(k.cameras[1].name, "cam1");
  EXPECT_DOUBLE_EQ(k.cameras[0].fx, 458.654);
  EXPECT_EQ(k.cameras[0].width_px, 752);
  EXPECT_EQ(k.cameras[0].distortion, c0.distortion);
  EXPECT_EQ(k.cameras[0].distortion_model, Distortion::kRadtan);
  EXPECT_TRUE(k.cameras[1].T_b_c.isApprox(c1.T_b_c, 1e-12));
  EXPECT_DOUBLE_EQ(k.timeshift_cam_imu_s, 0.0125);
  ASSERT_TRUE(k.imu_noise.has_value());
  EXPECT_DOUBLE_EQ(k.imu_noise->acc_noise_density, 0.0028);
  EXPECT_DOUBLE_EQ(k.imu_noise->gyr_random_walk, 2.2e-05);

  // cam1 from T_cn_cnm1 alone; a disagreeing pair is used as T_cam_imu, with a warning.
  std::string chained =
      cameraYaml("cam0", c0, 0.0) + "cam1:\n  T_cn_cnm1:\n" + matrixYaml(T_c1_c0, "  ") +
      cameraYaml("x", c1, 0.0).substr(cameraYaml("x", c1, 0.0).find("  camera_model"));
  test::writeText(dir.path() / "chained.yaml", chained);
  EXPECT_TRUE(readKalibr({dir.path() / "chained.yaml"}).cameras[1].T_b_c.isApprox(c1.T_b_c, 1e-9));
  Eigen::Matrix4d off = T_c1_c0;
  off(0, 3) += 0.01;
  test::writeText(
      dir.path() / "off.yaml",
      cameraYaml("cam0", c0, 0.0) +
          cameraYaml("cam1", c1, 0.0, "radtan", "  T_cn_cnm1:\n" + matrixYaml(off, "  ")));
  const KalibrCalibration warned = readKalibr({dir.path() / "off.yaml"});
  ASSERT_EQ(warned.warnings.size(), 1U);
  EXPECT_THAT(warned.warnings[0], HasSubstr("disagree by 0.0100 m"));

  // Into a dataset: cameras and noise replaced, frames moved into the IMU's clock.
  Dataset ds;
  ds.cameras.resize(2);
  ds.frames.resize(2);
  ds.frames[1].t_ns = 100'000'000;
  applyKalibr(ds, k);
  EXPECT_EQ(ds.cameras[0].fx, 458.654);
  EXPECT_EQ(ds.frames[0].t_ns, 12'500'000);
  EXPECT_EQ(ds.frames[1].t_ns, 112'500'000);
  ASSERT_TRUE(ds.imu_noise.has_value());
  ds.cameras.resize(1);
  EXPECT_THROW(applyKalibr(ds, k), InvalidInput);  // two calibrated cameras, one in the dataset
}

// TUM VI's fisheye chain (Kalibr's pinhole-equi): read as equidistant cameras, k1..k4 in order,
// which the rectifier takes as they are.
TEST(Kalibr, EquidistantCamchain) {
  test::TempDir dir("kalibr_equi");
  const CameraModel c0 = test::tumviCam0(), c1 = test::tumviCam1();
  test::writeText(dir.path() / "camchain.yaml", cameraYaml("cam0", c0, 0.0, "equidistant") +
                                                    cameraYaml("cam1", c1, 0.0, "equidistant"));
  const KalibrCalibration k = readKalibr({dir.path() / "camchain.yaml"});
  ASSERT_EQ(k.cameras.size(), 2U);
  EXPECT_TRUE(k.warnings.empty()) << k.warnings.front();
  for (std::size_t i = 0; i < 2; ++i) {
    const CameraModel& expected = i == 0 ? c0 : c1;
    EXPECT_EQ(k.cameras[i].distortion_model, Distortion::kEquidistant);
    EXPECT_EQ(k.cameras[i].distortion, expected.distortion);
    EXPECT_DOUBLE_EQ(k.cameras[i].fx, expected.fx);
    EXPECT_EQ(k.cameras[i].width_px, 512);
    EXPECT_TRUE(k.cameras[i].T_b_c.isApprox(expected.T_b_c, 1e-12));
  }
  const odometry::Rectifier rect(k.cameras[0], k.cameras[1]);
  EXPECT_FALSE(rect.isIdentity());
  EXPECT_NEAR(rect.baselineM(), 0.1011, 1e-3);

  // distortion_model none: a pinhole, whatever distortion_coeffs say.
  test::writeText(dir.path() / "none.yaml", cameraYaml("cam0", c0, 0.0, "none"));
  const KalibrCalibration pinhole = readKalibr({dir.path() / "none.yaml"});
  EXPECT_EQ(pinhole.cameras[0].distortion_model, Distortion::kRadtan);
  EXPECT_TRUE(pinhole.cameras[0].distortion.empty());
}

std::string kalibrError(const std::string& text) {
  test::TempDir dir("kalibr_bad");
  const fs::path file = dir.path() / "camchain.yaml";
  test::writeText(file, text);
  try {
    readKalibr({file});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Kalibr, BadFilesNameTheFileAndLine) {
  const CameraModel c0 = test::eurocCam0();
  EXPECT_THAT(kalibrError(cameraYaml("cam0", c0, 0.0, "fov")),
              AllOf(HasSubstr("camchain.yaml:9"), HasSubstr("cam0: distortion_model 'fov' is not "
                                                            "supported yet")));
  std::string five = cameraYaml("cam0", test::tumviCam0(), 0.0, "equidistant");
  five.replace(five.find("distortion_coeffs: ["), 20, "distortion_coeffs: [0.001, ");
  EXPECT_THAT(kalibrError(five), AllOf(HasSubstr("camchain.yaml:8"),
                                       HasSubstr("'distortion_coeffs' must be a list of 4")));
  EXPECT_THAT(kalibrError(cameraYaml("cam0", c0, 0.0, "banana")), HasSubstr("unknown distortion"));
  std::string no_t = cameraYaml("cam0", c0, 0.0);
  no_t.erase(no_t.find("  T_cam_imu"), no_t.find("  camera_model") - no_t.find("  T_cam_imu"));
  EXPECT_THAT(kalibrError(no_t), HasSubstr("missing 'T_cam_imu'"));
  std::string no_k = cameraYaml("cam0", c0, 0.0);
  no_k.replace(no_k.find("intrinsics"), 10, "intrinsix");
  EXPECT_THAT(kalibrError(no_k), HasSubstr("'intrinsics' must be a list of 4 numbers"));
  std::string sheared = cameraYaml("cam0", c0, 0.0);
  sheared.replace(sheared.find("- ["), 3, "- [2.0, 0, 0, 0]\n  #");
  EXPECT_THAT(kalibrError(sheared), AllOf(HasSubstr("camchain.yaml:3"), HasSubstr("not a rigid")));
  std::string flat = cameraYaml("cam0", c0, 0.0);
  const std::size_t fu = flat.find("intrinsics: [") + 13;
  flat.replace(fu, flat.find(',', fu) - fu, "0");  // a focal length of 0
  EXPECT_THAT(kalibrError(flat),
              AllOf(HasSubstr("camchain.yaml:2"),
                    HasSubstr("cam0: resolution and focal lengths must be positive")));
  EXPECT_THAT(kalibrError("foo: 1\n"), HasSubstr("neither a Kalibr camera chain"));
  EXPECT_THAT(kalibrError("imu0:\n  accelerometer_noise_density: -1\n  accelerometer_random_walk: "
                          "1\n  gyroscope_noise_density: 1\n  gyroscope_random_walk: 1\n"),
              HasSubstr("camchain.yaml:2"));
  EXPECT_THAT(kalibrError("cam0: [unclosed\n"), HasSubstr("camchain.yaml:"));
}

// The drive's pinhole images as an equidistant lens would have taken them: each fisheye pixel takes
// the pinhole image's value along its own ray (cv::fisheye::undistortPoints gives the ray).
// Rewrites the images of cameras 0 and 1 in `copy`, a copy of the dataset.
void seenThroughFisheye(const Dataset& ds, const fs::path& copy, const CameraModel& fisheye) {
  const cv::Mat K =
      (cv::Mat_<double>(3, 3) << fisheye.fx, 0, fisheye.cx, 0, fisheye.fy, fisheye.cy, 0, 0, 1);
  std::vector<cv::Point2d> px, rays;
  for (int v = 0; v < fisheye.height_px; ++v) {
    for (int u = 0; u < fisheye.width_px; ++u) px.emplace_back(u, v);
  }
  cv::fisheye::undistortPoints(px, rays, K, fisheye.distortion);
  std::vector<cv::Mat> map_x, map_y;
  for (std::size_t c = 0; c < 2; ++c) {
    const CameraModel& pinhole = ds.cameras[c];
    map_x.emplace_back(fisheye.height_px, fisheye.width_px, CV_32F);
    map_y.emplace_back(fisheye.height_px, fisheye.width_px, CV_32F);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const int u = static_cast<int>(i) % fisheye.width_px,
                v = static_cast<int>(i) / fisheye.width_px;
      map_x[c].at<float>(v, u) = static_cast<float>(pinhole.fx * rays[i].x + pinhole.cx);
      map_y[c].at<float>(v, u) = static_cast<float>(pinhole.fy * rays[i].y + pinhole.cy);
    }
  }
  for (const FrameRecord& frame : ds.frames) {
    for (std::size_t c = 0; c < 2; ++c) {
      const fs::path file = copy / frame.image_paths.at(c).lexically_relative(ds.root);
      const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(image.empty()) << file;
      cv::Mat out;
      cv::remap(image, out, map_x[c], map_y[c], cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      ASSERT_TRUE(cv::imwrite(file.string(), out)) << file;
    }
  }
}

// gvio run --calib with the simulated drive's own calibration written as Kalibr files gives the
// same run as the dataset's calibration files; the drive's images seen through an equidistant lens,
// with that lens as a Kalibr chain, run about as well; a fov chain exits 2 with one line.
TEST(CliKalibr, TheDrivesOwnCalibrationAsKalibrFilesGivesTheSameRun) {
  const fs::path drive = test::cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9", GVIO_SOURCE_DIR));
  const Dataset ds = readDataset(drive, std::nullopt, ReaderConfig{});
  ASSERT_EQ(ds.cameras.size(), 2U);
  test::TempDir dir("cli_kalibr");
  test::writeText(dir.path() / "camchain.yaml",
                  cameraYaml("cam0", ds.cameras[0], 0.0) + cameraYaml("cam1", ds.cameras[1], 0.0));
  const auto run = [&](const std::string& extra, const std::string& out, const fs::path& dataset) {
    return test::runGvio(fmt::format(
        "run --dataset {} --out {} --no-progress --gnss off --set map.enabled=false --set "
        "loops.enabled=false {}",
        test::quoted(dataset), test::quoted(dir.path() / out), extra));
  };
  const test::CommandResult own = run("", "own", drive);
  ASSERT_EQ(own.exit_code, 0) << own.err;
  const test::CommandResult kalibr =
      run("--calib " + test::quoted(dir.path() / "camchain.yaml"), "kalibr", drive);
  ASSERT_EQ(kalibr.exit_code, 0) << kalibr.err;
  const auto report = [&](const std::string& out) {
    return nlohmann::json::parse(test::readText(dir.path() / out / "report.json"));
  };
  const auto ape = [&](const std::string& out) {
    return report(out)["evaluation"]["ape_se3"]["rmse"].get<double>();
  };
  EXPECT_NEAR(ape("kalibr"), ape("own"), 1e-3);
  EXPECT_LT(ape("kalibr"), 0.5);
  EXPECT_EQ(report("kalibr")["rectification"]["distortion_model"], "none");

  // A lens of ~84 deg across the diagonal whose image holds nothing the pinhole image does not:
  // at its corners a pinhole model of the same focal length would be off by ~140 px.
  CameraModel fisheye = ds.cameras[0];
  fisheye.fx = fisheye.fy = 900.0;
  fisheye.distortion_model = Distortion::kEquidistant;
  fisheye.distortion = {0.02, -0.01, 0.005, -0.001};
  const fs::path fisheye_drive = dir.path() / "fisheye_drive";
  fs::copy(drive, fisheye_drive, fs::copy_options::recursive);
  seenThroughFisheye(ds, fisheye_drive, fisheye);
  CameraModel fisheye1 = fisheye;
  fisheye1.T_b_c = ds.cameras[1].T_b_c;
  test::writeText(dir.path() / "fisheye.yaml",
                  cameraYaml("cam0", fisheye, 0.0, "equidistant") +
                      cameraYaml("cam1", fisheye1, 0.0, "equidistant"));
  const test::CommandResult equi =
      run("--calib " + test::quoted(dir.path() / "fisheye.yaml"), "fisheye", fisheye_drive);
  ASSERT_EQ(equi.exit_code, 0) << equi.err;
  EXPECT_EQ(report("fisheye")["rectification"]["identity"], false);
  EXPECT_EQ(report("fisheye")["rectification"]["distortion_model"], "equidistant");
  EXPECT_NEAR(report("fisheye")["rectification"]["baseline_m"].get<double>(), 0.537, 1e-6);
  EXPECT_LT(ape("fisheye"), 0.5);
  std::printf(
      "APE (SE3): own calibration %.3f m, as Kalibr files %.3f m, the equidistant lens %.3f m\n",
      ape("own"), ape("kalibr"), ape("fisheye"));
  // gvio inspect names the model, in the text and the JSON.
  const test::CommandResult summary = test::runGvio(
      fmt::format("inspect --dataset {} --quick --no-progress --calib {} --json {}",
                  test::quoted(fisheye_drive), test::quoted(dir.path() / "fisheye.yaml"),
                  test::quoted(dir.path() / "summary.json")));
  ASSERT_EQ(summary.exit_code, 0) << summary.err;
  EXPECT_THAT(summary.out, HasSubstr("cy 185.216, equidistant distortion, p_b_c"));
  const auto models =
      nlohmann::json::parse(test::readText(dir.path() / "summary.json"))["cameras"]["models"];
  EXPECT_EQ(models[1]["distortion_model"], "equidistant");
  EXPECT_EQ(models[1]["distortion"].size(), 4U);

  test::writeText(dir.path() / "fov.yaml", cameraYaml("cam0", ds.cameras[0], 0.0, "fov") +
                                               cameraYaml("cam1", ds.cameras[1], 0.0, "fov"));
  const test::CommandResult bad =
      run("--calib " + test::quoted(dir.path() / "fov.yaml"), "bad", drive);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, AllOf(HasSubstr("fov.yaml:"), HasSubstr("'fov' is not supported")));
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

}  // namespace
}  // namespace gvio::io

namespace gvio::io {
namespace {

// What gvio simulate --format rosbag writes reads back as the same cameras, topics and noise.
TEST(KalibrWriter, RoundTripsThroughTheReader) {
  test::TempDir dir("kalibr_writer");
  CameraModel c0 = test::eurocCam0(), c1 = test::eurocCam1();
  c1.distortion_model = Distortion::kEquidistant;
  c1.distortion = {0.01, -0.002, 0.0003, -0.00004};
  test::writeText(dir.path() / "camchain.yaml",
                  kalibrCamchainYaml({c0, c1}, {"/left", "/right"}, -0.015));
  ImuNoise noise;
  noise.acc_noise_density = 0.003;
  test::writeText(dir.path() / "imu.yaml", kalibrImuYaml(noise, 200.0, "/imu"));
  const KalibrCalibration k = readKalibr({dir.path() / "camchain.yaml", dir.path() / "imu.yaml"});
  ASSERT_EQ(k.cameras.size(), 2U);
  EXPECT_EQ(k.camera_topics, (std::vector<std::string>{"/left", "/right"}));
  EXPECT_EQ(k.imu_topic, "/imu");
  EXPECT_DOUBLE_EQ(k.timeshift_cam_imu_s, -0.015);
  ASSERT_TRUE(k.imu_noise);
  EXPECT_DOUBLE_EQ(k.imu_noise->acc_noise_density, 0.003);
  const CameraModel* in[] = {&c0, &c1};
  for (std::size_t i = 0; i < 2; ++i) {
    const CameraModel& got = k.cameras[i];
    EXPECT_EQ(got.distortion_model, in[i]->distortion_model) << i;
    EXPECT_EQ(got.distortion, in[i]->distortion) << i;
    EXPECT_DOUBLE_EQ(got.fx, in[i]->fx);
    EXPECT_EQ(got.width_px, in[i]->width_px);
    EXPECT_LT((got.T_b_c.matrix() - in[i]->T_b_c.matrix()).cwiseAbs().maxCoeff(), 1e-12) << i;
  }
  EXPECT_TRUE(k.warnings.empty());  // T_cn_cnm1 agrees with the two T_cam_imu

  // OpenCV's five radtan coefficients (KITTI's calibration) are Kalibr's four when k3 is 0.
  c0.distortion = {0.01, -0.02, 0.001, 0.002, 0.0};
  test::writeText(dir.path() / "five.yaml", kalibrCamchainYaml({c0}, {"/left"}, 0.0));
  EXPECT_EQ(readKalibr({dir.path() / "five.yaml"}).cameras[0].distortion,
            (std::vector<double>{0.01, -0.02, 0.001, 0.002}));
  c0.distortion[4] = 0.003;
  EXPECT_THROW((void)kalibrCamchainYaml({c0}, {"/left"}, 0.0), InvalidInput);
}

}  // namespace
}  // namespace gvio::io
