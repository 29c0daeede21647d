#pragma once
// Tightly coupled sliding-window visual-inertial odometry (VINS-Mono/Fusion and OKVIS in spirit,
// Qin et al. 2018; Leutenegger et al. 2015): KLT front end, IMU preintegration (Forster 2017),
// Ceres optimisation of reprojection + IMU residuals over a window of keyframes, and
// marginalisation of leaving keyframes into a linear prior by Schur complement.
//
// Input contract: IMU samples and frames arrive in time order (IMU up to a frame's stamp before
// that frame). Cameras must be rectified pinhole cameras (no distortion; for stereo the right
// camera differs from the left only by a translation along the left x axis): app/ rectifies
// raw cameras with odometry::Rectifier first. The estimator never throws on odd data (black
// frames, gaps, time jumps): it coasts or reinitialises and records an event.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "odometry/feature_tracker.hpp"
#include "odometry/imu_preintegration.hpp"
#include "odometry/measurements.hpp"
#include "odometry/vio_config.hpp"

namespace gvio::odometry {

// Something the estimator did that a user should know about (report.json "events").
struct VioEvent {
  std::int64_t t_ns = 0;
  std::string kind;     // "initialized", "reinitialized", "lost", "coasting", "imu_gap",
                        // "time_jump", "dropped_frame", "black_frame", "waiting"
  std::string message;  // one human-readable line
};

struct FrameResult {
  std::int64_t t_ns = 0;
  // False until the estimator has initialised (then the fields below are meaningless).
  bool initialized = false;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();  // body (IMU) in the VIO world
  Eigen::Vector3d v_w_mps = Eigen::Vector3d::Zero();
  ImuBias bias;
  bool keyframe = false;
  int features = 0;             // features tracked in this frame
  int landmarks_in_window = 0;  // landmarks used by the optimisation
  // Wall-clock time of the two stages for this frame (informational, for report.json).
  double ms_tracking = 0.0;
  double ms_estimator = 0.0;
};

// A landmark of the window (for maps): position in the VIO world and its support.
struct LandmarkEstimate {
  std::uint64_t id = 0;
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  int observations = 0;               // window frames that observe it
  double mean_reprojection_px = 0.0;  // over those observations, left and right images
};

struct VioCounters {
  int frames = 0;
  int keyframes = 0;
  int initializations = 0;  // first initialisation included
  int lost_frames = 0;      // frames with too few features to estimate
  int coasted_frames = 0;   // frames propagated on the IMU alone
  int imu_gaps = 0;
  // Solves of the time offset that held it: the window's motion too steady to observe it.
  int time_offset_held_solves = 0;
  int time_offset_free_solves = 0;  // ... and those that estimated it
  // Frames whose exposure change the tracker removed (TrackerConfig::gain_threshold): against the
  // previous left image, and between the left and the right image.
  int exposure_corrected_frames = 0;
  int stereo_gain_corrected_frames = 0;
  // The tracker's TrackerStats summed over the frames (report.json's per-frame means): what a
  // world gives the front end (a sparse wall's 87 tracks a frame against a street's 198).
  std::int64_t tracked_features = 0, new_features = 0, rejected_forward_backward = 0,
               rejected_ransac = 0, stereo_matches = 0, rejected_stereo = 0;
};

class VioEstimator {
 public:
  // `left` always; `right` for the stereo modes. T_b_c of each camera is the camera in the body
  // (IMU) frame. Throws InvalidInput for an invalid config or cameras that break the contract.
  VioEstimator(const EstimatorConfig& config, const CameraModel& left,
               const std::optional<CameraModel>& right);
  ~VioEstimator();
  VioEstimator(const VioEstimator&) = delete;
  VioEstimator& operator=(const VioEstimator&) = delete;
  VioEstimator(VioEstimator&&) noexcept;
  VioEstimator& operator=(VioEstimator&&) noexcept;

  // Ignored (but counted) in the stereo-only mode.
  void addImu(const ImuSample& sample);
  // 8-bit grey images of the calibrated size (right empty in mono mode).
  FrameResult addFrame(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right = cv::Mat());

  // addFrame in its three steps, for a pipeline that tracks the next frame while this one is
  // estimated; the results are addFrame's, bit for bit:
  //   beginFrame(t)  the frame's time checks (false: the frame is ignored, as in addFrame);
  //   trackFrame     the front end, or takeAhead(trackAhead(...)) for a frame tracked ahead;
  //   processFrame   the estimator.
  // trackAhead(t1, ...) may run on another thread while processFrame(t0) runs, and only then: it
  // touches nothing but the front end, which processFrame never touches. Call it only for the
  // frame that comes next, when wouldAccept(t1) (which no processFrame changes), and hand its
  // result to takeAhead after beginFrame(t1): if a restart came between (it resets the front
  // end), the frame is tracked again after the reset, with the ids it would have had.
  bool beginFrame(std::int64_t t_ns);
  [[nodiscard]] bool wouldAccept(std::int64_t t_ns) const;
  TrackedFrame trackFrame(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right = cv::Mat());
  struct TrackAhead {
    std::int64_t t_ns = 0;
    TrackedFrame tracked;
    std::uint64_t next_id_before = 0;
    double ms_tracking = 0.0;
  };
  TrackAhead trackAhead(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right = cv::Mat());
  TrackedFrame takeAhead(TrackAhead&& ahead, const cv::Mat& left, const cv::Mat& right,
                         double& ms_tracking);
  FrameResult processFrame(std::int64_t t_ns, const TrackedFrame& tracked, double ms_tracking);

  // Events since the last call (moved out).
  std::vector<VioEvent> takeEvents();
  [[nodiscard]] const VioCounters& counters() const;
  // The camera-IMU time offset estimate t_d (image stamps minus exposures, s): 0 until an IMU
  // window estimates it (vio.estimate_time_offset), kept through restarts.
  [[nodiscard]] double timeOffsetS() const;
  // The front end's features of the last frame given to addFrame (rectified pixels; a feature's
  // id is its landmark's id).
  [[nodiscard]] const std::vector<Feature>& lastFeatures() const;
  // Landmarks currently in the window with a valid depth.
  [[nodiscard]] std::vector<LandmarkEstimate> landmarks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvio::odometry
