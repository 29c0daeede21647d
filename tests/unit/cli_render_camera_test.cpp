// gvio render --view camera (issue 19): the map drawn from the recorded left camera at one instant
// over its image. The map is built from the very images it is compared with, so with the run's own
// poses its grey levels repeat the image; a trajectory moved half a metre sideways does not.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"
#include "io/reader_config.hpp"
#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

// Zero-mean normalised cross-correlation of two grey images over the pixels the map covers.
double nccOverMap(const cv::Mat& map_bgr, const cv::Mat& image_grey) {
  cv::Mat map_grey;
  cv::cvtColor(map_bgr, map_grey, cv::COLOR_BGR2GRAY);
  const cv::Mat mask = map_grey > 0;
  cv::Scalar ma, sa, mb, sb;
  cv::meanStdDev(map_grey, ma, sa, mask);
  cv::meanStdDev(image_grey, mb, sb, mask);
  cv::Mat a, b;
  map_grey.convertTo(a, CV_64F, 1.0, -ma[0]);
  image_grey.convertTo(b, CV_64F, 1.0, -mb[0]);
  cv::Mat weight;
  mask.convertTo(weight, CV_64F, 1.0 / 255.0);
  const double n = cv::countNonZero(mask);
  return a.mul(b).dot(weight) / (n * sa[0] * sb[0]);
}

class CliRenderCamera : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("cli_render_camera");
    dataset_ = cachedSimulation(
        fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 8 --seed 4", GVIO_SOURCE_DIR));
    const CommandResult r = runGvio(
        fmt::format("run --dataset {} --out {} --no-progress --gnss off --set loops.enabled=false",
                    quoted(dataset_), quoted(run())));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path run() { return dir_->path() / "run"; }
  static std::string out(const std::string& name) { return (dir_->path() / name).string(); }
  // The recorded left image nearest 4 s into the drive (the simulator's cameras are rectified).
  static cv::Mat imageAt4s() {
    const io::Dataset ds = io::readDataset(dataset_, std::nullopt, io::ReaderConfig{});
    const Trajectory vio = io::readTum(run() / "trajectory_vio.tum");
    const std::int64_t t = vio.t_ns.front() + 4'000'000'000LL;
    std::size_t best = 0;
    for (std::size_t i = 0; i < ds.frames.size(); ++i) {
      if (std::llabs(ds.frames[i].t_ns - t) < std::llabs(ds.frames[best].t_ns - t)) best = i;
    }
    return io::loadFrameImage(ds, best, 0);
  }

  static TempDir* dir_;
  static fs::path dataset_;
};
TempDir* CliRenderCamera::dir_ = nullptr;
fs::path CliRenderCamera::dataset_;

TEST_F(CliRenderCamera, TheMapRepeatsTheImageFromTheRunsPoseAndNotFromADisplacedOne) {
  const std::string args = " --view camera --at 4 --overlay none --map-colour intensity --ahead 0";
  CommandResult r = runGvio("render --run " + quoted(run()) + args + " --out " + out("own.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat image = imageAt4s();
  const cv::Mat own = cv::imread(out("own.png"));
  ASSERT_EQ(own.size(), image.size());
  cv::Mat own_grey;
  cv::cvtColor(own, own_grey, cv::COLOR_BGR2GRAY);
  const double covered = cv::countNonZero(own_grey) / static_cast<double>(own_grey.total());

  // The same run with every pose 0.5 m to the left of the drive (the map stays).
  const fs::path moved = dir_->path() / "moved";
  fs::create_directories(moved);
  for (const char* f : {"map.pcd", "report.json", "config.yaml"}) fs::copy(run() / f, moved / f);
  Trajectory vio = io::readTum(run() / "trajectory_vio.tum");
  for (auto& T : vio.poses) T.translation() += T.rotation() * Eigen::Vector3d(0.0, 0.5, 0.0);
  io::writeTum(moved / "trajectory_vio.tum", vio);
  r = runGvio("render --run " + quoted(moved) + args + " --out " + out("moved.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const double ncc_own = nccOverMap(own, image);
  const double ncc_moved = nccOverMap(cv::imread(out("moved.png")), image);
  RecordProperty("ncc_own", std::to_string(ncc_own));
  RecordProperty("ncc_moved", std::to_string(ncc_moved));
  EXPECT_GT(covered, 0.3);
  std::printf("map over the image: NCC %.3f from the run's pose, %.3f moved 0.5 m sideways\n",
              ncc_own, ncc_moved);
  EXPECT_GT(ncc_own, 0.7) << ncc_moved;
  EXPECT_LT(ncc_moved, ncc_own - 0.15) << ncc_own;
}

TEST_F(CliRenderCamera, BlendAndEdgesDrawTheMapAndThePathOverTheImage) {
  for (const char* overlay : {"blend", "edges"}) {
    const std::string png = out(std::string(overlay) + ".png");
    const CommandResult r = runGvio("render --run " + quoted(run()) +
                                    " --view camera --at 2 --overlay " + overlay + " --out " + png);
    ASSERT_EQ(r.exit_code, 0) << overlay << ": " << r.err;
    const cv::Mat img = cv::imread(png);
    ASSERT_FALSE(img.empty());
    cv::Mat hsv;
    cv::cvtColor(img, hsv, cv::COLOR_BGR2HSV);
    std::vector<cv::Mat> ch;
    cv::split(hsv, ch);
    // Coloured pixels: the depth-coloured map (blend) or its yellow outlines (edges), and the
    // magenta path (hue ~155 of 180).
    const double coloured = cv::countNonZero(ch[1] > 80) / static_cast<double>(img.total());
    const int magenta = cv::countNonZero((ch[0] > 145) & (ch[0] < 165) & (ch[1] > 150));
    EXPECT_GT(coloured, std::string(overlay) == "blend" ? 0.3 : 0.005) << overlay;
    EXPECT_GT(magenta, 200) << overlay;
  }
}

TEST_F(CliRenderCamera, BadRequestsExitTwoWithOneLine) {
  const std::string base = "render --run " + quoted(run()) + " --out " + out("bad.png");
  CommandResult r = runGvio(base + " --view camera");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--at"));
  r = runGvio(base + " --view camera --at 500");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("no image within"));
  r = runGvio(base + " --view camera --at 1 --overlay bright");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("expected blend, edges or none"));
  r = runGvio(base + " --view topdown --at 1");
  EXPECT_EQ(r.exit_code, 2);

  // A report without "sources" (an older run): --dataset names the dataset instead.
  const fs::path old_run = dir_->path() / "old_run";
  fs::create_directories(old_run);
  for (const char* f : {"map.pcd", "trajectory_vio.tum", "config.yaml"}) {
    fs::copy(run() / f, old_run / f);
  }
  nlohmann::json report = nlohmann::json::parse(readText(run() / "report.json"));
  report.erase("sources");
  writeText(old_run / "report.json", report.dump());
  const std::string old_args =
      "render --run " + quoted(old_run) + " --view camera --at 1 --out " + out("old.png");
  r = runGvio(old_args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("report.json"));
  EXPECT_THAT(r.err, HasSubstr("--dataset"));
  r = runGvio(old_args + " --dataset " + quoted(dataset_));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

}  // namespace
}  // namespace gvio::test

namespace gvio::test {
namespace {

struct VideoFile {
  int frames = 0, width = 0, height = 0;
  cv::Mat first, last;
};

VideoFile readVideo(const std::string& file) {
  cv::VideoCapture capture(file);
  VideoFile v;
  cv::Mat frame;
  while (capture.read(frame)) {
    if (v.frames == 0) v.first = frame.clone();
    v.last = frame.clone();
    ++v.frames;
  }
  v.width = v.first.cols;
  v.height = v.first.rows;
  return v;
}

double whiteShare(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return cv::countNonZero(grey > 245) / static_cast<double>(grey.total());
}

// At 4x speed and 10 fps a frame every 0.4 s of the drive, from its first pose to its last.
TEST_F(CliRenderCamera, VideosOfEveryViewHaveOneFramePerStepOfTheDrive) {
  const Trajectory vio = io::readTum(run() / "trajectory_vio.tum");
  const int expected =
      static_cast<int>(static_cast<double>(vio.t_ns.back() - vio.t_ns.front()) * 1e-9 / 0.4) + 1;
  ASSERT_GT(expected, 10);
  const std::string base = "render --run " + quoted(run()) + " --speed 4 --no-progress";
  CommandResult r = runGvio(base + " --view follow --size 320x240 --video " + out("f.mp4"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const VideoFile follow = readVideo(out("f.mp4"));
  EXPECT_EQ(follow.frames, expected);
  EXPECT_EQ(follow.width, 320);
  EXPECT_EQ(follow.height, 240);

  r = runGvio(base + " --view topdown --size 320x240 --video " + out("t.avi"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const VideoFile top = readVideo(out("t.avi"));
  EXPECT_EQ(top.frames, expected);
  // The map is revealed as the drive goes on.
  EXPECT_GT(whiteShare(top.first), whiteShare(top.last) + 0.05);

  r = runGvio(base + " --view camera --overlay edges --video " + out("c.mp4"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const VideoFile camera = readVideo(out("c.mp4"));
  EXPECT_EQ(camera.frames, expected);
  EXPECT_EQ(camera.width, 1242);  // 1241 px padded to even for H.264's 4:2:0
  EXPECT_EQ(camera.height, 376);
  EXPECT_FALSE(fs::exists(out("c.mp4") + ".tmp"));
  for (const auto& e : fs::directory_iterator(dir_->path())) {
    EXPECT_EQ(e.path().filename().string().find("gvio-tmp"), std::string::npos) << e.path();
  }
}

TEST_F(CliRenderCamera, BadVideoRequestsExitTwo) {
  const std::string base = "render --run " + quoted(run()) + " --view follow --no-progress";
  CommandResult r = runGvio(base + " --video " + out("v.gif"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown video container"));
  r = runGvio(base + " --video " + out("v.mp4") + " --fps 0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--fps"));
  r = runGvio(base + " --video " + out("v.mp4") + " --out " + out("v.png"));
  EXPECT_EQ(r.exit_code, 2);
  r = runGvio("render --run " + quoted(run()) + " --video " + out("v.mp4") + " --view sideways");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("expected follow, topdown or camera"));
  EXPECT_FALSE(fs::exists(out("v.mp4")));
  // A file size limit (ulimit -f counts 1024-byte blocks) cuts the video short: refused, and
  // neither it nor its temporary is left.
  r = runGvioWithEnv("ulimit -f 20;", base + " --size 320x240 --video " + out("v.mp4"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("not written completely"));
  EXPECT_FALSE(fs::exists(out("v.mp4")));
  for (const auto& e : fs::directory_iterator(dir_->path())) {
    EXPECT_EQ(e.path().filename().string().find("gvio-tmp"), std::string::npos) << e.path();
  }
}

}  // namespace
}  // namespace gvio::test
