#pragma once
// Configuration of the sliding-window VIO estimator: plain structs with defaults and validate()
// (parsed from YAML in app/ only).
#include <string>

#include "odometry/feature_tracker.hpp"
#include "odometry/measurements.hpp"

namespace gvio::odometry {

enum class VioMode {
  kStereoImu,  // default: stereo camera + IMU
  kMonoImu,    // left camera + IMU (scale from the IMU)
  kStereo,     // stereo camera only (e.g. KITTI sync drives: 10 Hz oxts is no IMU)
};
std::string toString(VioMode mode);
// Parses "stereo-imu", "mono-imu", "stereo"; throws InvalidInput otherwise.
VioMode parseVioMode(const std::string& name);
[[nodiscard]] inline bool usesImu(VioMode m) {
  return m != VioMode::kStereo;
}
[[nodiscard]] inline bool usesStereo(VioMode m) {
  return m != VioMode::kMonoImu;
}

// What the marginalisation does with a landmark whose residuals it folds into the prior (one
// anchored in the leaving keyframe and seen again in the window). kDrop: it leaves with the
// frame, its observations in the frames that stay being in the prior already; the next keyframe
// that tracks it starts a new landmark. kReanchor: it moves to its next observation with its
// depth (VINS-Mono's removeBackShiftDepth), and those observations enter the solve again.
// kAuto: drop with the IMU, re-anchor with stereo alone (foldedLandmarksDropped()).
enum class FoldedLandmarks { kAuto, kDrop, kReanchor };
std::string toString(FoldedLandmarks policy);
// Parses "auto", "drop", "reanchor"; throws InvalidInput otherwise.
FoldedLandmarks parseFoldedLandmarks(const std::string& name);

struct EstimatorConfig {
  VioMode mode = VioMode::kStereoImu;
  TrackerConfig tracker;
  ImuNoise imu_noise;

  int window_size = 10;  // keyframes in the sliding window
  // Mean parallax since the last keyframe that makes a keyframe, as an angle (the feature's pixel
  // motion over the focal length), so that one setting means the same motion on any camera:
  // VINS-Mono's 10 px at its 460 px focal length is 1.25 deg; 0.8 deg is 10 px on KITTI (718 px).
  double keyframe_parallax_deg = 0.8;
  int keyframe_min_tracked = 50;  // fewer tracked landmarks than this makes a keyframe
  double pixel_sigma_px = 1.0;    // reprojection noise (1 sigma)
  double huber_sigmas = 2.0;      // robust (Huber) loss threshold in sigmas
  // Ceres iterations per frame (no wall-clock limit: the estimator is deterministic); 0 = by
  // mode (solverIterations()).
  int max_iterations = 0;
  double min_depth_m = 0.5;  // landmarks closer or further are not used
  // Far points barely constrain translation but are the best reference for rotation: 1000 m
  // (0.39 px of disparity on KITTI's stereo pair) keeps what the stereo match and the
  // triangulation give; 80 m before (docs/benchmarks/vio-matrix.md, "Each observation counted
  // once").
  double max_depth_m = 1000.0;
  FoldedLandmarks folded_landmarks = FoldedLandmarks::kAuto;  // see foldedLandmarksDropped()
  double max_reprojection_px = 3.0;  // landmarks with a larger residual after solving are dropped
  double static_gyr_radps = 0.02;    // static detection: gyro/acc spread and pixel motion below
  double static_acc_mps2 = 0.2;
  double static_pixel_motion_px = 0.5;
  double init_window_s = 1.0;  // frames used by the visual-inertial alignment
  // The alignment's gravity direction must be this certain (1-sigma of its own solve, deg) before
  // a moving window initialises: on large uniform walls a 1 s window's visual poses are too noisy,
  // and a start 4 deg tilted bends the first 10 s. After init_max_wait_s of uncertain alignments
  // it initialises anyway, with the tilt prior widened to the alignment's sigma.
  double init_max_tilt_sigma_deg = 1.0;
  double init_max_wait_s = 5.0;
  // While it waits, the moving stereo window keeps the poses of the frames it marginalises, and
  // the alignment reaches back over them up to this span before its newest frame: the gravity
  // direction comes from the visual positions' curvature against the IMU's, whose tilt leak grows
  // as the span squared. 0 = the window's own frames only.
  double init_alignment_span_s = 5.0;
  double max_imu_gap_s = 0.1;      // longer gaps without IMU: coast on the visual solution
  int min_features_tracking = 15;  // fewer usable features: the frame is lost (coast/reinit)
  // Priors on the state the IMU window starts from (after initialisation or a restart). With the
  // vehicle driving straight, tilt and accelerometer bias are nearly indistinguishable (1 m/s^2 of
  // bias = 5.8 deg of tilt), so a realistic bias prior is what keeps the tilt from drifting.
  double init_tilt_sigma_deg = 1.0;
  double init_velocity_sigma_mps = 0.5;
  double acc_bias_prior_mps2 = 0.1;
  double gyr_bias_prior_radps = 0.01;
  // Camera-IMU time offset t_d (how much image stamps lag the exposures, s) as a window state
  // (Qin and Shen 2018) when the IMU is in use; its prior around 0 (the calibration's timeshift
  // is applied to the stamps before the estimator sees them). On synchronised drives it costs
  // about 1 % APE over the style matrix (KITTI-00: APE 5 % better, RPE 15 % worse, as the estimate
  // wanders on straight stretches); unestimated, a 20 ms lag costs 2x on a car drive and 100x in a
  // slalom (docs/how-it-works/time-offset.md).
  bool estimate_time_offset = true;
  double time_offset_sigma_s = 0.05;
  // Random walk of t_d (s/sqrt(s)) added to its marginal at every marginalisation: on a car, t_d is
  // unobservable while the motion is straight and steady (a lag then equals a shift along the
  // track), and the information a long straight stretch appears to give (from model error) would
  // otherwise hold the estimate where it was until long after the first turn. 0 keeps it all.
  double time_offset_random_walk_s = 0.005;
  // t_d is held (not a variable of the solve) while the window's motion is near stationary: every
  // inter-frame interval's mean angular rate within time_offset_min_rate_change_radps of the
  // window's mean and its mean specific force within time_offset_min_force_change_mps2 (Li and
  // Mourikis 2014: t_d is unobservable under constant body-frame rates). Left free there, the
  // estimate follows model error, not the lag. The defaults are ten times and more what the
  // default IMU noise puts into a 0.1 s interval's mean (5e-4 rad/s, 6e-3 m/s^2) and far below a
  // turn or a braking: only steady motion is held (the demo drive's straights; 0.1 % of the solves
  // of the simulated KITTI-00 drive, whose recorded motion is never quite steady). 0 and 0 never
  // hold it.
  double time_offset_min_rate_change_radps = 0.005;
  double time_offset_min_force_change_mps2 = 0.1;
  // The value a hold keeps: the median of the last this-many free solves' t_d, not the last
  // one's. Where the motion is weakly excited the cost is nearly flat in t_d, and one solve can
  // move it far and the next bring it back (the demo drive's turn exit with a 15 px KLT window and
  // holds off: -3.8 -> -16.1 -> +0.3 ms): a hold starting after such a solve kept the outlier for
  // the whole straight that followed (docs/how-it-works/time-offset.md). 1: the last solve's.
  int time_offset_hold_median_solves = 10;

  // max_iterations, or by mode when 0: 2 with stereo+IMU, 4 otherwise. Measured, not derived:
  // with stereo+IMU two iterations gave KITTI-00 3.316 -> 3.225 m APE with 27 % less estimator
  // time and 14 of the 15 style-matrix drives better (the window solves each frame again at every
  // frame it stays in; why fewer per frame is better was not isolated). Stereo alone and mono+IMU
  // were not better with fewer (docs/benchmarks/vio-matrix.md, "Fewer solver iterations per
  // frame").
  [[nodiscard]] int solverIterations() const;
  // folded_landmarks, or by mode when kAuto: dropped with the IMU, where re-counting their
  // observations lets the vision pull the tilt / accelerometer-bias pair that a straight drive
  // cannot observe (stereo+IMU matrix: geometric mean 0.0522 -> 0.0452 % of the path, KITTI-00
  // 1.735 -> 1.614 m); re-anchored with stereo alone, where nothing competes with the vision and
  // the re-counted tracks hold the drift better (matrix 0.093 % re-anchored, 0.104 % dropped).
  [[nodiscard]] bool foldedLandmarksDropped() const;
  void validate() const;  // throws InvalidInput naming the field
};

}  // namespace gvio::odometry
