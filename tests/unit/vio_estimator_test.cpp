// Regression and robustness of the sliding-window VIO on simulated drives with exact truth (the
// committed demo trajectory, so no shared data is needed), and static behaviour on the real EuRoC
// clip when ../shared/data is present.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <utility>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "odometry/error.hpp"
#include "odometry/rectifier.hpp"
#include "odometry/vio_estimator.hpp"
#include "run/evaluation.hpp"
#include "run/frame_stepper.hpp"
#include "support/fixtures.hpp"

namespace gvio::odometry {
namespace {

struct RunOutput {
  Trajectory trajectory;
  std::vector<VioEvent> events;
  VioCounters counters;
  bool all_finite = true;

  [[nodiscard]] bool hasEvent(const std::string& kind) const {
    for (const auto& e : events) {
      if (e.kind == kind) return true;
    }
    return false;
  }
};

struct Perturbation {
  // Frames whose images are replaced by black ones.
  std::function<bool(std::size_t frame_index)> black = [](std::size_t) { return false; };
  // Frames never given to the estimator, IMU samples withheld.
  std::function<bool(std::size_t frame_index)> skip_frame = [](std::size_t) { return false; };
  std::function<bool(std::int64_t t_ns)> skip_imu = [](std::int64_t) { return false; };
  // Feed the frames through run::FrameStepper, tracking each next frame on another thread while
  // the current one is estimated (gvio run --threads >= 2), instead of addFrame.
  bool track_ahead = false;
  // Images resized by this factor and the cameras' intrinsics with them: the same scene through a
  // camera of another resolution and focal length.
  double image_scale = 1.0;
};

CameraModel scaled(CameraModel cam, double s) {
  if (s == 1.0) return cam;  // bit for bit the dataset's camera
  cam.width_px = static_cast<int>(std::lround(cam.width_px * s));
  cam.height_px = static_cast<int>(std::lround(cam.height_px * s));
  // Pixel centres at integer coordinates: x' + 0.5 = s (x + 0.5).
  cam.fx *= s;
  cam.fy *= s;
  cam.cx = s * (cam.cx + 0.5) - 0.5;
  cam.cy = s * (cam.cy + 0.5) - 0.5;
  return cam;
}

RunOutput runOn(const io::Dataset& ds, EstimatorConfig config, const Perturbation& p = {}) {
  // Mono: the left camera alone (rectified on its own, no right image needed).
  const bool stereo = usesStereo(config.mode) && ds.cameras.size() > 1;
  const CameraModel cam0 = scaled(ds.cameras[0], p.image_scale);
  const std::optional<CameraModel> cam1 =
      stereo ? std::optional<CameraModel>(scaled(ds.cameras[1], p.image_scale)) : std::nullopt;
  const Rectifier rectifier(cam0, cam1);
  if (ds.imu_noise) config.imu_noise = *ds.imu_noise;
  VioEstimator vio(config, rectifier.left(),
                   usesStereo(config.mode) ? rectifier.right() : std::nullopt);
  const auto rectified = [&](std::size_t k) {
    const io::FrameRecord& frame = ds.frames[k];
    cv::Mat left = io::loadGrayImage(frame.image_paths[0], ds.cameras[0]);
    cv::Mat right = usesStereo(config.mode) ? io::loadGrayImage(frame.image_paths[1], ds.cameras[1])
                                            : cv::Mat();
    if (p.image_scale != 1.0) {
      cv::resize(left, left, cv::Size(cam0.width_px, cam0.height_px), 0, 0, cv::INTER_AREA);
      if (!right.empty()) {
        cv::resize(right, right, cv::Size(cam1->width_px, cam1->height_px), 0, 0, cv::INTER_AREA);
      }
    }
    if (p.black(k)) {
      left.setTo(0);
      if (!right.empty()) right.setTo(0);
    }
    return rectifier.rectify(left, right);
  };
  RunOutput out;
  run::FrameStepper stepper(vio, true);
  std::optional<RectifiedImages> next_images;  // frame k + 1, loaded for the tracking ahead
  std::size_t imu_index = 0;
  for (std::size_t k = 0; k < ds.frames.size(); ++k) {
    const io::FrameRecord& frame = ds.frames[k];
    while (imu_index < ds.imu.size() && ds.imu[imu_index].t_ns <= frame.t_ns) {
      if (!p.skip_imu(ds.imu[imu_index].t_ns)) vio.addImu(ds.imu[imu_index]);
      ++imu_index;
    }
    if (p.skip_frame(k)) continue;
    const RectifiedImages rect =
        next_images ? *std::exchange(next_images, std::nullopt) : rectified(k);
    FrameResult r;
    if (p.track_ahead) {
      std::optional<run::FrameStepper::Next> next;
      if (k + 1 < ds.frames.size() && !p.skip_frame(k + 1)) {
        next_images = rectified(k + 1);
        next = run::FrameStepper::Next{ds.frames[k + 1].t_ns, &*next_images};
      }
      r = stepper.step(frame.t_ns, rect, next ? &*next : nullptr);
    } else {
      r = vio.addFrame(frame.t_ns, rect.left, rect.right);
    }
    if (!r.initialized) continue;
    if (!r.T_w_b.matrix().allFinite() || !r.v_w_mps.allFinite()) out.all_finite = false;
    out.trajectory.t_ns.push_back(r.t_ns);
    out.trajectory.poses.push_back(r.T_w_b);
  }
  out.events = vio.takeEvents();
  out.counters = vio.counters();
  return out;
}

double apeRmse(const io::Dataset& ds, const Trajectory& estimate) {
  const auto outcome = run::evaluateAgainstTruth(*ds.groundtruth, estimate);
  EXPECT_TRUE(outcome.result.has_value()) << outcome.error;
  return outcome.result ? outcome.result->ape_se3.rmse : 1e9;
}

// One 30 s simulated drive (232 m) shared by the tests below; simulated once per build.
class VioDrive : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto dir = test::cachedSimulation(fmt::format(
        "--trajectory {}/assets/demo/drive.tum --seconds 30 --seed 5", GVIO_SOURCE_DIR));
    dataset_ = std::make_unique<io::Dataset>(io::readDataset(dir, std::nullopt, {}));
  }
  static void TearDownTestSuite() { dataset_.reset(); }
  static const io::Dataset& ds() { return *dataset_; }

 private:
  static std::unique_ptr<io::Dataset> dataset_;
};
std::unique_ptr<io::Dataset> VioDrive::dataset_;

// The APE each prints is docs/how-it-works/vio.md's figure; the bounds leave room for platform
// differences in floating point, not for a regression.
TEST_F(VioDrive, StereoImuRegression) {
  EstimatorConfig config;
  const RunOutput out = runOn(ds(), config);
  EXPECT_TRUE(out.all_finite);
  EXPECT_EQ(out.counters.initializations, 1);
  // Initialised within the first 1.5 s, every frame after that estimated.
  ASSERT_FALSE(out.trajectory.empty());
  EXPECT_LE(out.trajectory.t_ns.front() - ds().frames.front().t_ns, 1'500'000'000);
  EXPECT_GE(out.trajectory.size() + 15, ds().frames.size());
  const double ape = apeRmse(ds(), out.trajectory);
  std::printf("stereo+IMU: APE RMSE %.3f m\n", ape);
  EXPECT_LT(ape, 0.25);
}

TEST_F(VioDrive, StereoOnlyRegression) {
  EstimatorConfig config;
  config.mode = VioMode::kStereo;
  const RunOutput out = runOn(ds(), config);
  EXPECT_TRUE(out.all_finite);
  EXPECT_EQ(out.trajectory.size(), ds().frames.size());
  const double ape = apeRmse(ds(), out.trajectory);
  std::printf("stereo: APE RMSE %.3f m\n", ape);
  EXPECT_LT(ape, 0.25);
}

TEST_F(VioDrive, MonoImuInitialisesWhileMoving) {
  // The drive starts at 8 m/s and keeps that speed, so the scale is unobservable until the first
  // turn (from 10.2 s, 3 m/s^2 centripetal): the window initialises from the mono SfM then.
  EstimatorConfig config;
  config.mode = VioMode::kMonoImu;
  const RunOutput out = runOn(ds(), config);
  EXPECT_TRUE(out.all_finite);
  EXPECT_TRUE(out.hasEvent("waiting"));
  EXPECT_TRUE(out.hasEvent("initialized"));
  EXPECT_EQ(out.counters.initializations, 1);
  ASSERT_FALSE(out.trajectory.empty());
  EXPECT_LE(out.trajectory.t_ns.front() - ds().frames.front().t_ns, 11'000'000'000);
  // Every frame after the initialisation estimated.
  EXPECT_GE(out.trajectory.size() + 115, ds().frames.size());
  EXPECT_EQ(out.trajectory.t_ns.back(), ds().frames.back().t_ns);
  const double ape = apeRmse(ds(), out.trajectory);
  std::printf("mono+IMU: initialised at %.1f s, APE RMSE %.3f m\n",
              1e-9 * static_cast<double>(out.trajectory.t_ns.front() - ds().frames.front().t_ns),
              ape);
  EXPECT_LT(ape, 0.75);
}

// A moving stereo window waits while the alignment's gravity direction is uncertain
// (vio.init_max_tilt_sigma_deg), and no longer than vio.init_max_wait_s: with a threshold that no
// alignment meets, it initialises init_max_wait_s after the first alignment (at 1 s), widening
// its tilt prior to what the alignment knows.
TEST_F(VioDrive, WaitsForACertainGravityDirectionAtMostTheConfiguredTime) {
  EstimatorConfig config;
  config.init_max_tilt_sigma_deg = 1e-6;
  config.init_max_wait_s = 2.0;
  Perturbation p;
  p.skip_frame = [](std::size_t k) { return k >= 80; };  // 8 s
  const RunOutput out = runOn(ds(), config, p);
  EXPECT_TRUE(out.all_finite);
  bool waited = false;
  for (const auto& e : out.events) {
    if (e.kind == "waiting" && e.message.find("gravity direction uncertain") != std::string::npos)
      waited = true;
  }
  EXPECT_TRUE(waited);
  EXPECT_EQ(out.counters.initializations, 1);
  ASSERT_FALSE(out.trajectory.empty());
  const std::int64_t start_ns = out.trajectory.t_ns.front() - ds().frames.front().t_ns;
  EXPECT_GE(start_ns, 2'900'000'000);
  EXPECT_LE(start_ns, 3'300'000'000);
  EXPECT_LT(apeRmse(ds(), out.trajectory), 0.25);
  // (With the default 1 deg this drive starts at once: StereoImuRegression.)
}

// While it waits, the window keeps the poses of the frames it marginalises, and the alignment
// reaches back over them (vio.init_alignment_span_s): after 2 s of waiting it spans 3 s instead of
// the window's 1 s, and its gravity direction is several times more certain (the tilt leaks into
// the positions as the span squared). Measured on this drive: 0.037 deg over 31 frames (3.0 s)
// against 0.162 deg over 11 frames (1.0 s).
TEST_F(VioDrive, TheWaitingAlignmentReachesBackOverTheMarginalisedFrames) {
  struct Alignment {
    int frames = 0;
    double span_s = 0.0;
    double tilt_sigma_deg = 0.0;
  };
  const auto alignmentOf = [this](const EstimatorConfig& config) {
    Perturbation p;
    p.skip_frame = [](std::size_t k) { return k >= 40; };  // 4 s
    const RunOutput out = runOn(ds(), config, p);
    Alignment a;
    for (const auto& e : out.events) {
      if (e.kind != "initialized") continue;
      const auto over = e.message.find(" over ");
      const auto tilt = e.message.find("tilt +- ");
      if (over == std::string::npos || tilt == std::string::npos) continue;
      EXPECT_EQ(
          std::sscanf(e.message.c_str() + over, " over %d frames (%lf s)", &a.frames, &a.span_s), 2)
          << e.message;
      EXPECT_EQ(std::sscanf(e.message.c_str() + tilt, "tilt +- %lf", &a.tilt_sigma_deg), 1);
    }
    return a;
  };
  EstimatorConfig config;
  config.init_max_tilt_sigma_deg = 1e-6;  // never certain enough: initialises after the wait
  config.init_max_wait_s = 2.0;
  const Alignment reaching = alignmentOf(config);
  config.init_alignment_span_s = 0.0;
  const Alignment window_only = alignmentOf(config);
  fmt::print(
      "alignment: {} frames over {:.1f} s, tilt +- {:.3f} deg; window only: {} frames over "
      "{:.1f} s, +- {:.3f} deg\n",
      reaching.frames, reaching.span_s, reaching.tilt_sigma_deg, window_only.frames,
      window_only.span_s, window_only.tilt_sigma_deg);
  EXPECT_GE(reaching.span_s, 2.8);
  EXPECT_GE(reaching.frames, 25);
  EXPECT_LE(window_only.span_s, 1.2);
  EXPECT_LE(window_only.frames, 12);
  EXPECT_GT(window_only.tilt_sigma_deg, 0.0);
  EXPECT_LT(reaching.tilt_sigma_deg, 0.5 * window_only.tilt_sigma_deg);
}

// The keyframe threshold is an angle: the same drive seen through a camera of 0.6 x the
// resolution and focal length (so every pixel motion is 0.6 x as long) makes about as many
// keyframes, where the same threshold in pixels (0.8 deg / 0.6 on this camera) makes far fewer.
TEST_F(VioDrive, TheKeyframeRateDoesNotDependOnTheFocalLength) {
  EstimatorConfig config;
  config.mode = VioMode::kStereo;  // the keyframe rule is the same with an IMU, and this is faster
  Perturbation p;
  p.skip_frame = [](std::size_t k) { return k >= 60; };  // 6 s at 7.7 m/s
  const int full = runOn(ds(), config, p).counters.keyframes;
  p.image_scale = 0.6;
  const RunOutput small = runOn(ds(), config, p);
  EXPECT_EQ(small.counters.initializations, 1);
  const int same_angle = small.counters.keyframes;
  config.keyframe_parallax_deg /= p.image_scale;  // what the same pixel threshold would be
  const int same_pixels = runOn(ds(), config, p).counters.keyframes;
  fmt::print("keyframes of 60 frames: {} at full size, {} at 0.6 x, {} with the pixel threshold\n",
             full, same_angle, same_pixels);
  EXPECT_NEAR(same_angle, full, 0.1 * full) << "pixel threshold: " << same_pixels;
  EXPECT_LT(same_pixels, 0.8 * full) << "angle threshold: " << same_angle;
}

TEST_F(VioDrive, CoastsThroughBlackFramesOnTheImu) {
  EstimatorConfig config;
  Perturbation p;
  p.black = [](std::size_t k) { return k >= 150 && k < 155; };  // 0.5 s of black frames
  const RunOutput out = runOn(ds(), config, p);
  EXPECT_TRUE(out.all_finite);
  EXPECT_TRUE(out.hasEvent("coasting"));
  EXPECT_GE(out.counters.coasted_frames, 5);
  EXPECT_GE(out.trajectory.size() + 15, ds().frames.size());  // coasted frames are estimated too
  EXPECT_LT(apeRmse(ds(), out.trajectory), 1.0);
}

TEST_F(VioDrive, SurvivesImuGapDroppedFramesAndATimeJump) {
  EstimatorConfig config;
  Perturbation p;
  const std::int64_t t0 = ds().frames.front().t_ns;
  p.skip_imu = [t0](std::int64_t t) { return t > t0 + 8'000'000'000 && t < t0 + 8'400'000'000; };
  // Two single dropped frames and a 2 s hole (a time jump).
  p.skip_frame = [](std::size_t k) { return k == 60 || k == 61 || (k >= 180 && k < 200); };
  const RunOutput out = runOn(ds(), config, p);
  EXPECT_TRUE(out.all_finite);
  EXPECT_TRUE(out.hasEvent("imu_gap"));
  EXPECT_TRUE(out.hasEvent("dropped_frame"));
  EXPECT_TRUE(out.hasEvent("time_jump"));
  EXPECT_GE(out.counters.initializations, 2);  // re-aligned after the jump
  // Still estimating at the end of the drive.
  ASSERT_FALSE(out.trajectory.empty());
  EXPECT_EQ(out.trajectory.t_ns.back(), ds().frames.back().t_ns);
}

TEST_F(VioDrive, StereoOnlyRestartsAfterBlackFrames) {
  EstimatorConfig config;
  config.mode = VioMode::kStereo;
  Perturbation p;
  p.black = [](std::size_t k) { return k >= 100 && k < 103; };
  const RunOutput out = runOn(ds(), config, p);
  EXPECT_TRUE(out.all_finite);
  EXPECT_TRUE(out.hasEvent("lost"));
  EXPECT_GE(out.counters.initializations, 2);
  EXPECT_EQ(out.trajectory.t_ns.back(), ds().frames.back().t_ns);
}

// Tracking the next frame while this one is estimated gives addFrame's results bit for bit, also
// when the window restarts in between (black frames: lost, coasting, restarts reset the front end,
// and the frame tracked ahead is tracked again after the reset, with the same feature ids).
TEST_F(VioDrive, TrackingAheadGivesTheSameResultsThroughRestarts) {
  for (const VioMode mode : {VioMode::kStereo, VioMode::kStereoImu}) {
    EstimatorConfig config;
    config.mode = mode;
    Perturbation p;
    p.black = [](std::size_t k) { return (k >= 100 && k < 103) || (k >= 150 && k < 175); };
    p.skip_frame = [](std::size_t k) { return k == 60 || k == 61; };
    const RunOutput in_turn = runOn(ds(), config, p);
    p.track_ahead = true;
    const RunOutput ahead = runOn(ds(), config, p);
    EXPECT_GE(in_turn.counters.initializations, 2) << toString(mode);  // restarts happened
    EXPECT_EQ(in_turn.trajectory.t_ns, ahead.trajectory.t_ns) << toString(mode);
    ASSERT_EQ(in_turn.trajectory.size(), ahead.trajectory.size());
    for (std::size_t i = 0; i < ahead.trajectory.size(); ++i) {
      ASSERT_TRUE(in_turn.trajectory.poses[i].matrix() == ahead.trajectory.poses[i].matrix())
          << toString(mode) << " pose " << i;
    }
    ASSERT_EQ(in_turn.events.size(), ahead.events.size());
    for (std::size_t i = 0; i < ahead.events.size(); ++i) {
      EXPECT_EQ(in_turn.events[i].kind, ahead.events[i].kind);
      EXPECT_EQ(in_turn.events[i].message, ahead.events[i].message);
    }
  }
}

TEST(VioEstimator, RefusesUnrectifiedOrIncompleteCameras) {
  CameraModel cam;
  cam.name = "cam0";
  cam.width_px = 640;
  cam.height_px = 480;
  cam.fx = cam.fy = 500;
  cam.cx = 320;
  cam.cy = 240;
  EstimatorConfig config;
  EXPECT_THROW(VioEstimator(config, cam, std::nullopt), InvalidInput);  // stereo needs a right
  CameraModel right = cam;
  right.T_b_c.translation() = Eigen::Vector3d(0.1, 0.02, 0);  // off the x axis
  EXPECT_THROW(VioEstimator(config, cam, right), InvalidInput);
  CameraModel distorted = cam;
  distorted.distortion = {0.1, 0, 0, 0};
  config.mode = VioMode::kMonoImu;
  EXPECT_THROW(VioEstimator(config, distorted, std::nullopt), InvalidInput);
  CameraModel fisheye = cam;  // k1..k4 = 0 is still a fisheye (r_d = theta), not a pinhole
  fisheye.distortion_model = Distortion::kEquidistant;
  fisheye.distortion = {0, 0, 0, 0};
  EXPECT_THROW(VioEstimator(config, fisheye, std::nullopt), InvalidInput);
  config.window_size = 1;
  EXPECT_THROW(VioEstimator(config, cam, std::nullopt), InvalidInput);
}

TEST(VioEstimatorEuroc, InitialisesAndHoldsStillOnTheRealClip) {
  const auto root = test::sharedData("euroc_v101_micro");
  if (root.empty()) GTEST_SKIP() << "shared data absent: euroc_v101_micro";
  const io::Dataset ds = io::readDataset(root, std::nullopt, {});
  const RunOutput out = runOn(ds, EstimatorConfig{});
  EXPECT_TRUE(out.all_finite);
  EXPECT_EQ(out.counters.initializations, 1);
  ASSERT_GE(out.trajectory.size(), 40U);
  // The vehicle stands still (1.7 cm of true motion over the clip): the estimate may not wander.
  double max_drift = 0.0;
  for (const auto& T : out.trajectory.poses) {
    max_drift =
        std::max(max_drift, (T.translation() - out.trajectory.poses.front().translation()).norm());
  }
  for (const auto& e : out.events) {
    if (e.kind == "initialized") std::printf("EuRoC: %s\n", e.message.c_str());
  }
  std::printf("EuRoC: the estimate moves %.1f mm in all\n", 1e3 * max_drift);
  EXPECT_LT(max_drift, 0.02);
}

}  // namespace
}  // namespace gvio::odometry
