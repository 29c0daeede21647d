#pragma once
// Internal state of VioEstimator (shared by vio_estimator.cpp and vio_initialization.cpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "odometry/feature_tracker.hpp"
#include "odometry/imu_buffer.hpp"
#include "odometry/sliding_window.hpp"
#include "odometry/vi_alignment.hpp"
#include "odometry/vio_estimator.hpp"

namespace gvio::odometry {

// False when the motion from `from` to `to` over dt_s is faster than a car-like platform moves or
// turns (a failed solve or a wrong PnP, not motion).
bool plausibleMotion(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double dt_s);

// The latest estimate of any frame (also of non-keyframes, which leave the window).
struct LatestState {
  bool valid = false;
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();
  ImuBias bias;
};

// The state of a window frame, at its state time (WindowFrame::stateNs).
LatestState stateOf(const WindowFrame& f);

// How far before its stamp a frame's state goes for a time offset t_d_s (WindowFrame::retime_ns):
// max(0, t_d). The IMU has arrived up to the stamp, not beyond, so a negative t_d stays with the
// pixel motion.
inline std::int64_t retimeNsFor(double t_d_s) {
  return static_cast<std::int64_t>(std::llround(std::max(0.0, t_d_s) * 1e9));
}

struct VioEstimator::Impl {
  Impl(const EstimatorConfig& c, const StereoGeometry& g);

  FrameResult process(std::int64_t t_ns, const TrackedFrame& tracked);

  // Stages of process().
  bool checkTime(std::int64_t t_ns);
  FrameResult coast(std::int64_t t_ns, const std::string& why);
  std::unique_ptr<WindowFrame> predictFrame(std::int64_t t_ns, const TrackedFrame& tracked);
  // How far before its stamp a new frame's state is placed (WindowFrame::retime_ns).
  [[nodiscard]] std::int64_t retimeNs(std::int64_t t_ns) const;
  // The state carried to to_ns on the IMU (which must cover the interval).
  [[nodiscard]] LatestState propagate(const LatestState& from, std::int64_t to_ns) const;
  // The result of a solved window frame, at its stamp.
  [[nodiscard]] LatestState atStamp(const WindowFrame& f) const;
  std::optional<Eigen::Isometry3d> predictVisual(const TrackedFrame& tracked,
                                                 std::int64_t retime_ns) const;
  bool isKeyframe(const WindowFrame& f, const TrackedFrame& tracked) const;
  // The features of `tracked` that are window landmarks seen in frame `frame_uid`, and their mean
  // image motion since then (keyframe parallax, static detection).
  struct Parallax {
    int count = 0;
    double mean_px = 0.0;
  };
  [[nodiscard]] Parallax parallaxTo(const TrackedFrame& tracked, std::uint64_t frame_uid) const;
  void addObservations(const WindowFrame& f, const TrackedFrame& tracked);
  void finishFrame(const WindowFrame& f);
  // Restarts the window at the latest estimate (lost tracking, long coasting, time jumps).
  void restart(std::int64_t t_ns, const std::string& kind, const std::string& why,
               bool keep_imu_alignment);
  // Anchors a window that just started (gauge and initial-state priors); with the IMU, the tilt
  // prior's 1-sigma is the config's or tilt_sigma_rad (what the alignment knows), the larger.
  void anchorWindow(double tilt_sigma_rad = 0.0);
  void event(std::int64_t t_ns, const std::string& kind, const std::string& message);

  // vio_initialization.cpp: gravity alignment of the visual window (static or in motion).
  bool tryInitialize(std::int64_t t_ns, const TrackedFrame& tracked);
  bool staticInitialize(std::int64_t t_ns, const TrackedFrame& tracked);
  bool motionInitialize(std::int64_t t_ns);
  bool monoInitialize(std::int64_t t_ns);
  // The prior on t_d for the initialisation when the window estimates it (else none).
  [[nodiscard]] std::optional<TimeOffsetPrior> timeOffsetPrior() const;
  // The re-timing of the window's frames (WindowFrame::retime_ns, s), the same for all of them
  // during the initialisation.
  [[nodiscard]] double windowRetimeS() const;
  // The alignment's t_d (relative to the re-timing) into the window, with its uncertainty when
  // the alignment observed it.
  void setInitialTimeOffset(const AlignmentResult& result);
  // Re-times the (not yet aligned) window to t_d_s: every frame's state to its stamp less
  // max(0, t_d_s), the IMU preintegrated again between them, the observations' base, and t_d set.
  // False (nothing changed) when that is the window's re-timing already or the IMU does not cover
  // it. After an alignment that observed t_d, the alignment runs again on the re-timed window:
  // left to the pixel motion of the window's first solves, whose velocities are noisy differences,
  // the offset came out attenuated (a 20 ms lag estimated at 19.1 ms, then pulled to 14.6 ms).
  bool retimeWindow(double t_d_s);
  // The visual-inertial alignment of `af` (the window's frames) with the t_d prior it is given
  // (`prior`, set here); when it observes t_d the window is re-timed to it (retimeWindow) and the
  // alignment runs again, with `af`'s preintegrations and `prior` taken from the re-timed window.
  // `history` is how many frames of alignment_history lead `af` (prependHistory); they are
  // rebuilt at the new re-timing.
  std::optional<AlignmentResult> alignRetimed(std::vector<AlignmentFrame>& af, bool mono,
                                              std::optional<TimeOffsetPrior>& prior,
                                              std::size_t& history);
  // The moving stereo window's frames for the alignment (visual poses, IMU between them).
  [[nodiscard]] std::vector<AlignmentFrame> windowAlignmentFrames() const;
  // True while marginalised frames are kept for the alignment (a moving stereo window with the
  // IMU, not yet aligned, init_alignment_span_s > 0).
  [[nodiscard]] bool keepsAlignmentHistory() const;
  // Keeps the pose of `f`, about to be marginalised, for the alignment; forgets what lies more
  // than init_alignment_span_s before the newest frame.
  void keepForAlignment(const WindowFrame& f);
  // Puts the kept frames (those the IMU covers without a gap, back from the window's oldest) in
  // front of the window's frames `af`, with the IMU between them at the window's re-timing;
  // returns how many.
  std::size_t prependHistory(std::vector<AlignmentFrame>& af) const;
  // Moves the window's poses from the exposures to the stamps by the alignment's t_d.
  void moveToStamps(const AlignmentResult& result);
  void reportWaiting(std::int64_t t_ns, const std::string& why);
  // False while a moving window's alignment is less certain in tilt than configured, until
  // init_max_wait_s after the first such alignment.
  bool tiltCertainEnough(std::int64_t t_ns, double tilt_sigma_rad);
  void applyAlignment(const Eigen::Matrix3d& R_w_v, const std::vector<Eigen::Vector3d>& v_v,
                      const ImuBias& bias, double tilt_sigma_rad = 0.0);

  [[nodiscard]] bool imuActive() const { return usesImu(config.mode) && imu_aligned; }

  EstimatorConfig config;
  StereoGeometry geometry;
  FeatureTracker tracker;
  // restart() asks for the tracker's reset; the next tracking does it (trackFrame, takeAhead), so
  // that a restart during processFrame never touches a tracker that is tracking ahead.
  bool tracker_reset_pending = false;
  ImuBuffer imu;
  SlidingWindow window;
  LatestState latest;
  std::vector<Feature> last_features;              // the front end's features of the last frame
  std::optional<Eigen::Isometry3d> previous_pose;  // the frame before `latest` (constant velocity)
  bool imu_aligned = false;  // the window is gravity-aligned with velocities and biases
  bool waiting_reported = false;
  // Frames the vision-only stereo window marginalised while waiting for its alignment: pose in the
  // visual frame and stamp (keepForAlignment).
  struct PastFrame {
    std::int64_t t_ns = 0;
    Eigen::Isometry3d T_v_b = Eigen::Isometry3d::Identity();
  };
  std::deque<PastFrame> alignment_history;
  // The first alignment that was refused as too uncertain in tilt (-1: none since the last start).
  std::int64_t uncertain_alignment_since_ns = -1;
  std::uint64_t next_uid = 1;
  std::int64_t last_frame_ns = -1;
  std::int64_t nominal_frame_ns = 0;
  std::int64_t coast_start_ns = -1;
  std::vector<VioEvent> events;
  VioCounters counters;
};

}  // namespace gvio::odometry
