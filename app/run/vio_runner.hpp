#pragma once
// gvio run's pipeline: the dataset's measurements in time order through the rectifier and the VIO
// estimator (IMU -> addImu, frames -> load, rectify, addFrame; GNSS only counted until fusion
// lands), collecting the trajectory, counters, events and per-frame timings for report.json.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "odometry/trajectory.hpp"
#include "odometry/vio_config.hpp"
#include "odometry/vio_estimator.hpp"

namespace gvio::run {

// An IMU slower than this is no IMU for VIO (KITTI sync drives: 10 Hz oxts).
inline constexpr double kMinImuRateHz = 50.0;

// 1 / median sample period of the dataset's IMU, 0 with fewer than two samples.
double imuRateHz(const io::Dataset& dataset);

// The sensor set for `mode` (config text: auto | stereo-imu | mono-imu | stereo). auto: stereo-imu
// with two cameras and an IMU of >= kMinImuRateHz, stereo with two cameras and no such IMU,
// mono-imu with one camera and such an IMU. Throws InvalidInput naming the dataset when it lacks
// what the mode needs.
odometry::VioMode chooseVioMode(const std::string& mode, const io::Dataset& dataset);

// Wall-clock milliseconds per processed frame, one entry per stage.
struct FrameTimings {
  std::vector<double> load_ms, rectify_ms, tracking_ms, estimator_ms, total_ms;
};

struct VioRunResult {
  odometry::VioMode mode = odometry::VioMode::kStereoImu;
  bool rectification_identity = true;  // the cameras were already rectified
  double baseline_m = 0.0;             // rectified stereo baseline, 0 in mono
  Trajectory trajectory;               // T_w_b (VIO world) of every initialised frame
  odometry::VioCounters counters;
  int frames_skipped_unreadable = 0;  // an image failed to load: the frame never reached the VIO
  int nonfinite_poses = 0;            // initialised frames whose pose was not finite (not written)
  std::size_t imu_samples = 0, gnss_fixes = 0;
  std::vector<odometry::VioEvent> events;
  // The camera-IMU time offset estimate (vio.estimate_time_offset with an IMU): its value at the
  // end and once per second of the drive (frame stamp, estimate), both in seconds. What the run
  // reports and retimes the map with is run/time_offset_summary's, from the free estimates.
  bool time_offset_estimated = false;
  double time_offset_s = 0.0;
  std::vector<std::pair<std::int64_t, double>> time_offset_history;
  std::vector<double> time_offset_free_estimates;  // t_d after each free solve, in order
  FrameTimings timings;
  double wall_s = 0.0;
  bool stopped = false;  // VioRunOptions::stop ended the run before the last frame
};

using ProgressFn = std::function<void(std::size_t frames_done, std::size_t frames_total)>;

// What the map and loop closure need of a keyframe, handed over as the estimator declares it
// (initialised, finite pose). It owns its data, so the keyframe work may run on another thread
// while the estimator goes on: the rectified pair (right empty in mono; images are never written
// after rectification, so they are shared, not copied), the window's landmarks and the front
// end's features at this frame.
struct KeyframeInput {
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  cv::Mat left, right;
  CameraModel left_camera;  // rectified
  double baseline_m = 0.0;  // 0 in mono
  std::vector<odometry::LandmarkEstimate> landmarks;
  std::vector<odometry::Feature> features;
};
using KeyframeFn = std::function<void(const KeyframeInput&)>;

struct VioRunOptions {
  ProgressFn progress;     // may be empty
  KeyframeFn on_keyframe;  // may be empty; called in keyframe order, from one thread at a time
  // 1: everything in order on the calling thread. >= 2: image decoding and rectification run
  // ahead on a thread of their own, and the keyframe hook on another (in keyframe order), while
  // the calling thread tracks and estimates. The outputs are the same bit for bit: no decision
  // depends on which thread finishes first.
  int threads = 1;
  // Polled before each frame; true stops the run there (VioRunResult::stopped). May be empty.
  std::function<bool()> stop;
};

// `config.mode` and `config.imu_noise` are the run's (chooseVioMode, dataset or imu.* noise); the
// tracker's stereo flag is set here from the mode. Throws InvalidInput for cameras the rectifier
// or estimator refuse; unreadable images only skip their frame (logged once per folder).
VioRunResult runVio(const io::Dataset& dataset, odometry::EstimatorConfig config,
                    const VioRunOptions& options = {});

}  // namespace gvio::run
