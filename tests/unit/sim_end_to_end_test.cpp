// gvio simulate end to end: the output reads back through the dataset reader, is byte-identical
// for a seed, has images a KLT front end can track, and its images, calibration, truth and
// world.ply agree geometrically.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <set>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "io/mesh_ply.hpp"
#include "io/trajectory_io.hpp"
#include "render/renderer.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

class SimEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("sim");
    io::writeTum(dir_->path() / "drive.tum", demoDrive());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  // 3 s of the embedded demo drive, simulated once per build for all the tests below.
  static fs::path out() {
    return cachedSimulation(
        fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 3 --seed 7", GVIO_SOURCE_DIR));
  }
  static std::unique_ptr<TempDir> dir_;
};
std::unique_ptr<TempDir> SimEndToEnd::dir_;

TEST_F(SimEndToEnd, ReadsBackAsKittiRaw) {
  const io::Dataset ds = io::readDataset(out(), std::nullopt, {});
  EXPECT_EQ(ds.format, io::DatasetFormat::kKittiRaw);
  EXPECT_EQ(ds.variant, "extract");
  ASSERT_EQ(ds.cameras.size(), 2u);
  EXPECT_EQ(ds.cameras[0].width_px, 1241);
  EXPECT_EQ(ds.cameras[0].height_px, 376);
  EXPECT_NEAR(ds.cameras[0].fx, 718.856, 1e-9);
  EXPECT_NEAR((ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm(), 0.537,
              1e-3);
  EXPECT_EQ(ds.frames.size(), 31u);  // 3 s at 10 Hz, both ends
  EXPECT_EQ(ds.imu.size(), 301u);    // 100 Hz
  EXPECT_EQ(ds.gnss.size(), 4u);     // 1 Hz
  ASSERT_TRUE(ds.groundtruth);
  EXPECT_EQ(ds.groundtruth->size(), 301u);
  EXPECT_TRUE(fs::exists(out() / "world" / "world.ply"));
  EXPECT_TRUE(fs::exists(out() / "sim.yaml"));
  EXPECT_TRUE(fs::exists(out() / "gnss" / "data.csv"));
  // True biases next to the noisy IMU: 301 samples + header.
  const std::string truth = readText(out() / "imu_truth.csv");
  EXPECT_EQ(std::count(truth.begin(), truth.end(), '\n'), 302);
  for (const auto& f : ds.frames) {
    for (std::size_t c = 0; c < 2; ++c)
      EXPECT_NO_THROW(io::loadGrayImage(f.image_paths[c], ds.cameras[c]));
  }
}

std::map<std::string, std::string> allFiles(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), root).string()] = readText(e.path());
  }
  return files;
}

TEST_F(SimEndToEnd, SameSeedIsByteIdentical) {
  const std::string traj = (dir_->path() / "drive.tum").string();
  ASSERT_EQ(
      runGvio(fmt::format("simulate --trajectory {} --seconds 1 --seed 7 --out {} --no-progress",
                          traj, (dir_->path() / "b").string()))
          .exit_code,
      0);
  // The default world style named explicitly is the same drive.
  ASSERT_EQ(runGvio(fmt::format("simulate --trajectory {} --seconds 1 --seed 7 --world-style "
                                "street --out {} --no-progress",
                                traj, (dir_->path() / "c").string()))
                .exit_code,
            0);
  ASSERT_EQ(
      runGvio(fmt::format("simulate --trajectory {} --seconds 1 --seed 8 --out {} --no-progress",
                          traj, (dir_->path() / "d").string()))
          .exit_code,
      0);
  const auto b = allFiles(dir_->path() / "b"), c = allFiles(dir_->path() / "c"),
             d = allFiles(dir_->path() / "d");
  EXPECT_EQ(b.size(), c.size());
  for (const auto& [name, bytes] : b)
    EXPECT_TRUE(c.count(name) && c.at(name) == bytes) << name << " differs";
  EXPECT_NE(b.at("image_00/data/0000000005.png"), d.at("image_00/data/0000000005.png"));
}

// The front-end realism bar: >= 300 Shi-Tomasi corners (quality 0.01, min distance 10)
// per frame, and pyramidal KLT keeps >= 80 % of them to the next frame.
TEST_F(SimEndToEnd, EveryFrameHasTrackableTexture) {
  const io::Dataset ds = io::readDataset(out(), std::nullopt, {});
  std::size_t min_corners = 1u << 30;
  double min_kept = 1.0;
  for (std::size_t k = 0; k + 1 < ds.frames.size(); ++k) {
    const cv::Mat a = io::loadGrayImage(ds.frames[k].image_paths[0], ds.cameras[0]);
    const cv::Mat b = io::loadGrayImage(ds.frames[k + 1].image_paths[0], ds.cameras[0]);
    std::vector<cv::Point2f> corners, tracked;
    cv::goodFeaturesToTrack(a, corners, 2000, 0.01, 10);
    std::vector<std::uint8_t> status;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(a, b, corners, tracked, status, err);
    const double kept =
        static_cast<double>(std::count(status.begin(), status.end(), 1)) / corners.size();
    min_corners = std::min(min_corners, corners.size());
    min_kept = std::min(min_kept, kept);
  }
  std::cout << "[ sim ] min corners " << min_corners << ", min KLT kept " << min_kept << "\n";
  EXPECT_GE(min_corners, 300u);
  EXPECT_GE(min_kept, 0.8);
}

// Corners of the left image are lifted to 3-D with depth rendered from world.ply at the true pose,
// projected into the right camera with the written calibration, and compared with where KLT finds
// them in the right image.
TEST_F(SimEndToEnd, WorldPointsProjectWhereTheCalibrationSays) {
  const io::Dataset ds = io::readDataset(out(), std::nullopt, {});
  const io::TriangleMesh mesh = io::readMeshPly(out() / "world" / "world.ply");
  render::Scene scene;
  scene.textures.push_back(render::Texture{1, 1, 1, {128}});
  render::TexturedMesh m;
  m.vertices = mesh.vertices;
  m.uv.assign(mesh.vertices.size(), Eigen::Vector2f::Zero());
  for (const auto& t : mesh.triangles) m.indices.insert(m.indices.end(), t.begin(), t.end());
  scene.meshes.push_back(std::move(m));
  const render::EglContext context;
  const render::Renderer renderer(context);
  const render::GpuScene gpu(scene);
  const auto& cam0 = ds.cameras[0];
  const auto& cam1 = ds.cameras[1];
  render::PinholeIntrinsics K{cam0.fx,       cam0.fy,        cam0.cx, cam0.cy,
                              cam0.width_px, cam0.height_px, 0.3,     400.0};
  render::Framebuffer fb(K.width, K.height);
  std::vector<double> errors;
  for (const std::size_t k : {5u, 15u, 25u}) {
    const auto& frame = ds.frames[k];
    const auto it = std::find(ds.groundtruth->t_ns.begin(), ds.groundtruth->t_ns.end(), frame.t_ns);
    ASSERT_NE(it, ds.groundtruth->t_ns.end());
    const Eigen::Isometry3d T_w_b =
        ds.groundtruth->poses[static_cast<std::size_t>(it - ds.groundtruth->t_ns.begin())];
    const render::DepthImage depth =
        renderer.renderDepth(gpu, render::pinholeCamera(K, T_w_b * cam0.T_b_c), fb);
    const cv::Mat left = io::loadGrayImage(frame.image_paths[0], cam0);
    const cv::Mat right = io::loadGrayImage(frame.image_paths[1], cam1);
    std::vector<cv::Point2f> corners, predicted, tracked;
    cv::goodFeaturesToTrack(left, corners, 400, 0.01, 10);
    std::vector<cv::Point2f> kept;
    for (const auto& c : corners) {
      const float z =
          depth.at(static_cast<int>(std::lround(c.x)), static_cast<int>(std::lround(c.y)));
      if (z <= 0.5F || z > 60.0F) continue;  // no surface, or too far for a meaningful disparity
      const double zd = static_cast<double>(z);
      const Eigen::Vector3d p_c0((static_cast<double>(c.x) - K.cx) / K.fx * zd,
                                 (static_cast<double>(c.y) - K.cy) / K.fy * zd, zd);
      const Eigen::Vector3d p_c1 = cam1.T_b_c.inverse() * cam0.T_b_c * p_c0;
      kept.push_back(c);
      predicted.emplace_back(static_cast<float>(K.fx * p_c1.x() / p_c1.z() + K.cx),
                             static_cast<float>(K.fy * p_c1.y() / p_c1.z() + K.cy));
    }
    std::vector<std::uint8_t> status;
    std::vector<float> err;
    tracked = predicted;
    cv::calcOpticalFlowPyrLK(
        left, right, kept, tracked, status, err, cv::Size(21, 21), 3,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 0.001),
        cv::OPTFLOW_USE_INITIAL_FLOW);
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (status[i])
        errors.push_back(std::hypot(static_cast<double>(tracked[i].x - predicted[i].x),
                                    static_cast<double>(tracked[i].y - predicted[i].y)));
    }
  }
  ASSERT_GT(errors.size(), 200u);
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2),
                   errors.end());
  const double median = errors[errors.size() / 2];
  std::cout << "[ sim ] stereo reprojection: median " << median << " px over " << errors.size()
            << " points\n";
  EXPECT_LT(median, 0.5);
}

TEST_F(SimEndToEnd, EurocMonoReadsBack) {
  const fs::path out_dir = dir_->path() / "euroc";
  const auto r = runGvio(fmt::format(
      "simulate --trajectory {} --seconds 1 --format euroc --camera mono --gnss-noise rtk "
      "--out {} --no-progress",
      (dir_->path() / "drive.tum").string(), out_dir.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::Dataset ds = io::readDataset(out_dir, std::nullopt, {});
  EXPECT_EQ(ds.format, io::DatasetFormat::kEuroc);
  ASSERT_EQ(ds.cameras.size(), 1u);
  EXPECT_EQ(ds.frames.size(), 11u);
  EXPECT_EQ(ds.imu.size(), 101u);
  EXPECT_EQ(ds.gnss.size(), 2u);
  EXPECT_NEAR(ds.gnss.front().sigma_h_m, 0.02, 1e-9);
  ASSERT_TRUE(ds.imu_noise);
  ASSERT_TRUE(ds.groundtruth);
  EXPECT_EQ(ds.groundtruth->size(), 101u);
  EXPECT_FALSE(fs::exists(out_dir / "mav0" / "cam1"));
}

double sharpness(const cv::Mat& grey) {
  cv::Mat lap;
  cv::Laplacian(grey, lap, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(lap, mean, stddev);
  return stddev[0] * stddev[0];
}

// Sensor effects are opt-in config keys: motion blur lowers sharpness, exposure change brightness.
TEST_F(SimEndToEnd, MotionBlurAndExposureChange) {
  const std::string traj = (dir_->path() / "drive.tum").string();
  auto run = [&](const std::string& name, const std::string& sets) {
    const auto r = runGvio(
        fmt::format("simulate --trajectory {} --seconds 0.6 --seed 3 --out {} --no-progress {}",
                    traj, (dir_->path() / name).string(), sets));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return cv::imread((dir_->path() / name / "image_00" / "data" / "0000000005.png").string(),
                      cv::IMREAD_GRAYSCALE);
  };
  const cv::Mat plain = run("plain", "--set sim.image_noise_dn=0");
  const cv::Mat blurred =
      run("blur",
          "--set sim.image_noise_dn=0 --set sim.motion_blur=true --set sim.exposure_time_s=0.02");
  const cv::Mat bright = run(
      "bright",
      "--set sim.image_noise_dn=0 --set sim.exposure_change=true --set sim.exposure_period_s=2");
  ASSERT_FALSE(plain.empty());
  EXPECT_LT(sharpness(blurred), 0.9 * sharpness(plain));
  // At t = 0.5 s of a 2 s period the gain is 1 + 0.15 sin(pi / 2) = 1.15.
  EXPECT_GT(cv::mean(bright)[0], 1.08 * cv::mean(plain)[0]);
  // A right camera exposed 20 % brighter: its image only.
  const auto right = [&](const std::string& name) {
    return cv::imread((dir_->path() / name / "image_01" / "data" / "0000000005.png").string(),
                      cv::IMREAD_GRAYSCALE);
  };
  const cv::Mat left_of_brighter_right = run("right",
                                             "--set sim.image_noise_dn=0 --set "
                                             "sim.right_camera_gain=1.2");
  EXPECT_EQ(cv::norm(left_of_brighter_right, plain, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::mean(right("right"))[0], 1.12 * cv::mean(right("plain"))[0]);
}

// --world-style (or sim.world_style) picks the world: recorded in sim.yaml, another world.ply.
TEST_F(SimEndToEnd, WorldStyleReachesTheWorld) {
  const std::string traj = (dir_->path() / "drive.tum").string();
  for (const char* style : {"street", "open_road"}) {
    const auto r = runGvio(fmt::format(
        "simulate --trajectory {} --seconds 0.3 --seed 7 --world-style {} --out {} --no-progress",
        traj, style, (dir_->path() / style).string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr(fmt::format("{} world", style)));
    const YAML::Node yaml = YAML::LoadFile((dir_->path() / style / "sim.yaml").string());
    EXPECT_EQ(yaml["config"]["sim"]["world_style"].as<std::string>(), style);
  }
  EXPECT_NE(readText(dir_->path() / "street" / "world" / "world.ply"),
            readText(dir_->path() / "open_road" / "world" / "world.ply"));
}

// sim.imu_noise_scale_min/max: the drive's IMU noise is drawn per seed and stated where the
// layout can (sim.yaml always, EuRoC's imu0/sensor.yaml too); by default it is imu.* exactly.
TEST_F(SimEndToEnd, ImuNoiseRangeIsDrawnAndRecorded) {
  const ImuNoise nominal;
  const YAML::Node plain = YAML::LoadFile((out() / "sim.yaml").string())["imu_noise"];
  EXPECT_EQ(plain["acc_noise_density"].as<double>(), nominal.acc_noise_density);
  EXPECT_EQ(plain["gyr_random_walk"].as<double>(), nominal.gyr_random_walk);
  for (const auto& scale : plain["scale"]) EXPECT_EQ(scale.as<double>(), 1.0);

  const fs::path out_dir = dir_->path() / "imu_range";
  const auto r = runGvio(fmt::format(
      "simulate --trajectory {} --seconds 0.3 --seed 11 --format euroc --set "
      "sim.imu_noise_scale_min=0.5 --set sim.imu_noise_scale_max=4 --out {} --no-progress",
      (dir_->path() / "drive.tum").string(), out_dir.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node drawn = YAML::LoadFile((out_dir / "sim.yaml").string())["imu_noise"];
  const io::Dataset ds = io::readDataset(out_dir, std::nullopt, {});
  ASSERT_TRUE(ds.imu_noise);
  const std::array<std::pair<const char*, std::pair<double, double>>, 4> quantities{{
      {"acc_noise_density", {ds.imu_noise->acc_noise_density, nominal.acc_noise_density}},
      {"gyr_noise_density", {ds.imu_noise->gyr_noise_density, nominal.gyr_noise_density}},
      {"acc_random_walk", {ds.imu_noise->acc_random_walk, nominal.acc_random_walk}},
      {"gyr_random_walk", {ds.imu_noise->gyr_random_walk, nominal.gyr_random_walk}},
  }};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& [key, values] = quantities[i];
    const double value = drawn[key].as<double>(), scale = drawn["scale"][i].as<double>();
    std::cout << "[ sim ] " << key << " " << value << " (x " << scale << ")\n";
    EXPECT_DOUBLE_EQ(values.first, value) << key;  // the dataset states what the drive has
    EXPECT_DOUBLE_EQ(value, scale * values.second) << key;
    EXPECT_GE(scale, 0.5) << key;
    EXPECT_LE(scale, 4.0) << key;
    EXPECT_NE(scale, 1.0) << key;
  }
}

// sim.imu_turn_on_*: the drive's turn-on biases are drawn per seed, stated in sim.yaml and in
// the IMU data (the mean of measured minus true over 0.3 s); none by default.
TEST_F(SimEndToEnd, ImuTurnOnBiasIsDrawnRecordedAndInTheData) {
  const YAML::Node plain = YAML::LoadFile((out() / "sim.yaml").string())["imu_noise"];
  for (const auto& v : plain["turn_on_acc_bias_mps2"]) EXPECT_EQ(v.as<double>(), 0.0);
  for (const auto& v : plain["turn_on_gyr_bias_radps"]) EXPECT_EQ(v.as<double>(), 0.0);

  const fs::path out_dir = dir_->path() / "turn_on";
  const auto r = runGvio(fmt::format(
      "simulate --trajectory {} --seconds 0.3 --seed 11 --gnss-noise none --set "
      "sim.imu_turn_on_acc_bias_mps2=0.3 --set sim.imu_turn_on_gyr_bias_radps=0.01 --out {} "
      "--no-progress",
      (dir_->path() / "drive.tum").string(), out_dir.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("IMU turn-on bias: acc ["));
  const YAML::Node drawn = YAML::LoadFile((out_dir / "sim.yaml").string())["imu_noise"];
  Eigen::Vector3d acc, gyr;
  for (int i = 0; i < 3; ++i) {
    acc[i] = drawn["turn_on_acc_bias_mps2"][i].as<double>();
    gyr[i] = drawn["turn_on_gyr_bias_radps"][i].as<double>();
  }
  std::cout << "[ sim ] turn-on acc " << acc.transpose() << " gyr " << gyr.transpose() << "\n";
  EXPECT_GT(acc.norm(), 0.0);
  EXPECT_GT(gyr.norm(), 0.0);
  // Gyro: the body rates of a car over 0.3 s are smooth, so measured minus the truth's finite
  // rotation rate averages to the bias within the white noise (1.7e-4 rad/s/sqrt(Hz) at 100 Hz
  // over 30 samples: ~3e-4 rad/s).
  const io::Dataset ds = io::readDataset(out_dir, std::nullopt, {});
  const Trajectory gt = io::readTum(out_dir / "groundtruth.tum");  // the body at the IMU rate
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (std::size_t k = 0; k + 1 < gt.size(); ++k) {
    const double dt = 1e-9 * static_cast<double>(gt.t_ns[k + 1] - gt.t_ns[k]);
    const Eigen::AngleAxisd step(gt.poses[k].linear().transpose() * gt.poses[k + 1].linear());
    const auto it = std::find_if(ds.imu.begin(), ds.imu.end(),
                                 [&](const ImuSample& s) { return s.t_ns == gt.t_ns[k]; });
    if (it == ds.imu.end() || std::next(it) == ds.imu.end()) continue;
    const Eigen::Vector3d measured = 0.5 * (it->gyr_b_radps + std::next(it)->gyr_b_radps);
    sum += measured - step.axis() * step.angle() / dt;
    ++n;
  }
  ASSERT_GT(n, 10);
  EXPECT_LT((sum / n - gyr).norm(), 1e-3) << (sum / n).transpose();
}

TEST_F(SimEndToEnd, BadInputIsOneLineExit2) {
  const fs::path d = dir_->path();
  writeText(d / "three.tum", "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n");
  writeText(d / "back.tum",
            "0 0 0 0 0 0 0 1\n0.2 1 0 0 0 0 0 1\n0.1 2 0 0 0 0 0 1\n0.3 3 0 0 0 0 0 1\n");
  const std::string traj = (d / "drive.tum").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"simulate --trajectory " + (d / "missing.tum").string() + " --out " + (d / "x1").string(),
       "missing.tum"},
      {"simulate --trajectory " + (d / "three.tum").string() + " --out " + (d / "x2").string(),
       "at least 4"},
      {"simulate --trajectory " + (d / "back.tum").string() + " --out " + (d / "x3").string(),
       "not increasing"},
      {"simulate --trajectory " + traj + " --gnss-outage 50:60 --out " + (d / "x4").string(),
       "outside the drive"},
      {"simulate --trajectory " + traj + " --gnss-outage 5 --out " + (d / "x5").string(), "T0:T1"},
      {"simulate --trajectory " + traj + " --seconds 1 --out " + out().string(), "not empty"},
      {"simulate --trajectory " + traj + " --world-style foo --out " + (d / "x6").string(),
       "--world-style 'foo'"},
      {"simulate --trajectory " + traj + " --set sim.world_style=Street --out " +
           (d / "x7").string(),
       "sim.world_style"},
      {"simulate --trajectory " + traj + " --set sim.imu_noise_scale_max=0.5 --out " +
           (d / "x8").string(),
       "sim.imu_noise_scale_max"},
      {"simulate --trajectory " + traj + " --set sim.imu_turn_on_acc_bias_mps2=-1 --out " +
           (d / "x9").string(),
       "sim.imu_turn_on_acc_bias_mps2"},
      {"simulate --trajectory " + traj + " --set sim.right_camera_gain=0 --out " +
           (d / "x10").string(),
       "sim.right_camera_gain"},
  };
  for (const auto& [args, needle] : cases) {
    const auto r = runGvio(args + " --no-progress");
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << args;
  }
}

}  // namespace
}  // namespace gvio::test
